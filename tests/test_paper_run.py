"""The real-data paper run: one config over cmu.yaml + samba.yaml, results in results/paper/,
families whose data are unavailable skipped with one line, mesh archives checked frame by frame."""

import gzip
import hashlib
import tarfile

import pytest

from conftest import copy_workflow, run_snakemake

pytestmark = pytest.mark.workflow
PAPER = ["--configfile", "config/cmu.yaml", "config/samba.yaml", "config/paper.yaml"]


def test_without_mirror_or_meshes_the_real_families_are_skipped(tmp_path):
    wd = copy_workflow(tmp_path / "wd")
    res = run_snakemake(wd, "-n", *PAPER, "--config", f"cmu_mirror={tmp_path / 'no_mirror'}",
                        f"mesh_dir={tmp_path / 'no_meshes'}")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    skip_lines = [ln for ln in out.splitlines() if ln.startswith("animsynth: skipping")]
    assert len(skip_lines) == 2, skip_lines  # one line per unavailable source
    assert "simplicial and resequencing" in skip_lines[0] and "no_mirror" in skip_lines[0]
    assert "meshdetail" in skip_lines[1] and "no_meshes" in skip_lines[1]
    for rule in ("download_trial", "simplicial_fold", "meshdetail_load"):
        assert f"\n{rule} " not in out, rule
    assert "facegraph_graph" in out  # the synthetic CK+-layout study still runs
    assert "results/paper/summary.md" in out


def test_paper_run_plans_every_family_into_results_paper(tmp_path, cmu_dir, cmu_many_dir, vlasic_dir):
    wd = copy_workflow(tmp_path / "wd")
    crane = tmp_path / "crane.yaml"  # the copied workflow is elsewhere: point crane at the data folder
    crane.write_text(f"meshdetail:\n  sequences:\n    crane:\n      mesh_dir: {vlasic_dir / 'crane'}\n")
    res = run_snakemake(wd, "-n", *PAPER, str(crane), "--config", f"cmu_mirror={cmu_dir.parent}",
                        f"cmu_many_mirror={cmu_many_dir.parent}", f"mesh_dir={vlasic_dir / 'samba'}")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    assert "animsynth: skipping" not in out
    for rule in ("download_trial", "simplicial_fold", "resequencing_path", "mesh_checksums", "meshdetail_load",
                 "facegraph_graph", "summary"):
        assert rule in out, rule
    assert "results/paper/simplicial/" in out and "results/paper/meshdetail/" in out
    for seq in ("samba", "crane"):  # both sequences, each checked against its checksum list, with the LBS floor
        assert f"results/paper/meshdetail/{seq}/dembones.csv" in out and f"data/mesh_checksums/{seq}.csv" in out
    assert "results/paper/meshdetail/sequences.csv" in out
    assert "results/simplicial/" not in out  # nothing of the default run is touched


def test_an_unreadable_second_mirror_leaves_only_its_trials_out_of_the_comparison(tmp_path, cmu_dir):
    """cmu_many_mirror absent: one line names it, the comparison keeps the subjects of cmu_mirror, the other
    families plan as before (none of them reads those trials)."""
    wd = copy_workflow(tmp_path / "wd")
    res = run_snakemake(wd, "-n", *PAPER, "--config", f"cmu_mirror={cmu_dir.parent}",
                        f"cmu_many_mirror={tmp_path / 'no_many'}", f"mesh_dir={tmp_path / 'no_meshes'}")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-4000:]
    lines = [ln for ln in out.splitlines() if ln.startswith("animsynth: compare: leaving out")]
    assert len(lines) == 1 and "no_many" in lines[0] and "07_01" in lines[0] and "06_01" in lines[0], lines
    assert "compare_clips" in out and "simplicial_fold" in out and "resequencing_path" in out
    assert "download_bvh_trial" not in out  # the BVH trials are all in the unreadable mirror
    assert "trials/07_01.npz" not in out and "trials/09_01.npz" in out


def _sequence_archive(tmp_path, corrupt=None):
    frames = {f"mesh_{i:04d}.obj": f"v 0 0 0\nv 1 0 0\nv 0 1 {i}\nf 1 2 3\n".encode() for i in range(4)}
    sums = tmp_path / "sums.sha256"
    sums.write_text("".join(f"{hashlib.sha256(b).hexdigest()}  {n}\n" for n, b in frames.items()))
    arch = tmp_path / "seq.tar.gz"
    with tarfile.open(arch, "w:gz") as t:
        for n, b in frames.items():
            p = tmp_path / "src" / f"{n}.gz"
            p.parent.mkdir(exist_ok=True)
            p.write_bytes(gzip.compress(b"v 9 9 9\n" + b if n == corrupt else b))
            t.add(p, arcname=f"seq/{n}.gz")
    return arch, sums


@pytest.mark.parametrize("corrupt", [None, "mesh_0002.obj"])
def test_mesh_archive_is_unpacked_and_checked(tmp_path, corrupt):
    wd = copy_workflow(tmp_path / "wd")
    arch, sums = _sequence_archive(tmp_path, corrupt)
    res = run_snakemake(wd, "results/data/mesh_checksums/seq.csv", "--config", f"mesh_dir={arch}", f"mesh_sha256={sums}")
    out = res.stdout + res.stderr
    if corrupt is None:
        assert res.returncode == 0, out[-4000:]
        got = sorted(p.name for p in (wd / "results" / "resources" / "mesh" / "seq").glob("*.obj.gz"))
        assert got == [f"mesh_{i:04d}.obj.gz" for i in range(4)]
        assert (wd / "results" / "data" / "mesh_checksums" / "seq.csv").read_text().count("\n") == 5
    else:
        assert res.returncode != 0
        # the fetch checks the frames in its temporary folder: the mismatch is its error, and nothing is left
        log = (wd / "logs" / "data" / "mesh_fetch" / "seq.log").read_text()
        assert "mesh_0002.obj" in log and "SHA-256" in log, log[-2000:]
        assert not (wd / "results" / "resources" / "mesh" / "seq").exists()
        assert not (wd / "results" / "data" / "mesh_checksums" / "seq.csv").exists()
