"""Turn a copy of the workflow into the comparison's design before its 20-second track and its per-subject jobs,
for the paired cost measurement of docs/compare/long_track.md ("Cost").

Usage::

    python benchmarks/compare_split_cost.py COPY      # COPY: a checkout or copy of the project, never the repository

In ``COPY``, ``workflow/rules/compare.smk`` then runs each generator over every subject in one job
(``compare_all_<generator>``; fairmotion's rows and budget sweep in one job, ``compare_all_fairmotion``), each row
through the same :func:`animsynth.compare.jobs.run_rows` as the committed rules, so that every table but the timing
tables is the same; the benchmark aggregation lists these jobs' files. ``config/before_split.yaml`` switches the long
track off and keeps the claims of ``config/config.yaml`` that are not on the long track. Then, in ``COPY``::

    python3 run.py paper --configfile config/before_split.yaml --config cmu_mirror=... mesh_dir=...

is the paper run before (its ``run_cost.csv`` total), and the same command without ``--configfile`` in an
unpatched copy the run after. Both on one machine, one after the other, as quiet as it can be.

The rewrite keys on the committed rule file's text (from ``rule compare_run:`` to the ``CMP_METRICS`` list, and
the compare part of ``compare_benchmarks`` in common.smk): it stops with a message when that text has changed.
"""

from __future__ import annotations

import sys
from pathlib import Path

import yaml

#: the rules that replace the committed generator rules (one job per generator over every subject)
RULES = r'''
from types import SimpleNamespace as _NS

_ALL_OUT = {**CMP_OUT, **CMP_LONG_OUT}


def _subject_outputs(rows, sweeps):
    """{s<subject>__<prefix><key>: path} for every subject: the rows' files, then each sweep budget's."""
    out = {}
    for s in CMP_SUBJECTS:
        for g, prefix in rows:
            for k, v in _ALL_OUT.items():
                out[f"s{s}__{prefix}{k}"] = v.replace("{cmpsubj}", s).replace("{cmpgen}", g)
        for i, (g, b) in enumerate(sweeps):
            for k, ext in (("metrics", ".csv"), ("timing", "_timing.csv")):
                out[f"s{s}__sweep{i}_{k}"] = R(f"compare/sweep/{s}/{g}_{b}{ext}")
    return out


def _all_subjects(rows, sweeps):
    """The params of one job over every subject: each subject's rows as compare_rows gives them."""
    return {s: compare_rows(_NS(cmpsubj=s), [(g, None, p) for g, p in rows]
                            + [(g, b, f"sweep{i}_") for i, (g, b) in enumerate(sweeps)]) for s in CMP_SUBJECTS}


_BEFORE_JOBS = {g: ([(g, "")], [(g, b) for b in CMP_SWEEP] if g in CMP_SWEEP_GRAPH else [])
                for g in [g for g in CMP_RUN if g not in CMP_FM]}
if CMP_FM:
    _BEFORE_JOBS["fairmotion"] = ([(g, f"{g}_") for g in CMP_FM], CMP_FM_SWEEP)

for _job, (_rows, _sweeps) in _BEFORE_JOBS.items():

    rule:
        name:
            f"compare_all_{_job}"
        input:
            expand(CMP_CLIPS, cmpsubj=CMP_SUBJECTS),
        output:
            **_subject_outputs(_rows, _sweeps),
        params:
            subjects=CMP_SUBJECTS,
            rows=_all_subjects(_rows, _sweeps),
            seed=config["seed"],
        threads: 1
        log:
            L(f"compare/run_all/{_job}.log"),
        benchmark:
            B(f"compare/run_all/{_job}.tsv")
        script:
            "../scripts/compare_run_all.py"


'''

BENCHMARKS = '''        job_benchmarks("compare_clips", cmpsubj=CMP_SUBJECTS)
        + [B(f"compare/run_all/{g}.tsv") for g in CMP_RUN if g not in CMP_FM]
        + ([B("compare/run_all/fairmotion.tsv")] if CMP_FM and n else [])
'''

SCRIPT = '''"""One generator (or fairmotion's rows and sweep) over every subject in one job: the comparison before its
per-subject jobs (benchmarks/compare_split_cost.py; measurement only)."""
from animsynth.compare.jobs import run_rows
from animsynth.workflow_utils import setup_logging

log = setup_logging(snakemake)
p, o = snakemake.params, snakemake.output
for i, subject in enumerate(p.subjects):
    run_rows(snakemake.input[i], p.rows[subject], p.seed, lambda name, s=subject: getattr(o, f"s{s}__{name}"))
'''


def _between(text: str, start: str, stop: str, what: str) -> tuple[int, int]:
    a, b = text.find(start), text.find(stop)
    if a < 0 or b < 0 or b < a:
        raise SystemExit(f"compare_split_cost: {what}: cannot find {start!r} ... {stop!r} (the rules changed; "
                         "update benchmarks/compare_split_cost.py)")
    return a, b


def before_split(copy: Path) -> None:
    """Rewrite the workflow of ``copy`` in place (see the module docstring)."""
    copy = copy.resolve()
    if copy == Path(__file__).resolve().parents[1]:
        raise SystemExit("compare_split_cost: give a copy of the project, not the repository itself")
    smk = copy / "workflow" / "rules" / "compare.smk"
    text = smk.read_text()
    a, b = _between(text, "rule compare_run:", "CMP_METRICS = [", str(smk))
    smk.write_text(text[:a] + RULES.lstrip("\n") + text[b:])
    common = copy / "workflow" / "rules" / "common.smk"
    text = common.read_text()
    a, b = _between(text, '        job_benchmarks("compare_clips", cmpsubj=CMP_SUBJECTS)',
                    '        + job_benchmarks("compare_tables")', str(common))
    common.write_text(text[:a] + BENCHMARKS + text[b:])
    (copy / "workflow" / "scripts" / "compare_run_all.py").write_text(SCRIPT)
    claims = yaml.safe_load((copy / "config" / "config.yaml").read_text())["compare"]["claims"]
    short = [c for c in claims if c.get("track", "short") != "long"]
    (copy / "config" / "before_split.yaml").write_text(
        "# the comparison before its 20-second track (benchmarks/compare_split_cost.py): long track off, the claims\n"
        "# of config/config.yaml that are not on the long track\n"
        + yaml.safe_dump({"compare": {"long_track": {"enabled": False}, "claims": short}}, sort_keys=False))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    before_split(Path(sys.argv[1]))
    print(f"compare_split_cost: {sys.argv[1]} now runs one comparison job per generator over every subject")
