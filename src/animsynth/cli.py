"""``animsynth``: one-off use of the library outside Snakemake.

    animsynth amc2bvh SKEL.asf MOTION.amc OUT.bvh
    animsynth preview SKEL.asf MOTION.amc OUT.gif        (or: preview WALK.bvh OUT.gif)
    animsynth generate --method delaunay TRAIN.amc ... --asf SKEL.asf --start-frame 0 --steps 300 OUT.bvh
    animsynth generate A.bvh B.bvh OUT.bvh
    animsynth resequence SKEL.asf MOTION.amc --start 10 --end 300 OUT.bvh   (or: resequence WALK.bvh ...)
    animsynth face --labels fear,surprise,happy OUT.gif
    animsynth score GENERATED.bvh ... --reference HELD_OUT.bvh [--database DB.bvh ...] --out scores.csv

Every command that reads a motion takes a BVH file as well as an ASF/AMC
pair. A BVH file is read as the workflow reads a trial
(:func:`animsynth.data.load_trial`): its unit (``--length-to-m``, e.g. 0.01
for centimetres, 0.05644 for cgspeed's CMU conversions), joint roles
(``--role left_hip=Bip01_L_Thigh``) and axes (``--up-axis``,
``--forward-axis``; default detected) may be given for all files or for one
(``--length-to-m walk.bvh=0.01``, ``--role walk.bvh:head=Kopf``); the motion
is turned into the canonical frame (+y up, +z forward) and written so.

``animsynth COMMAND --help`` explains each. Every argument is checked before
any work (types and ranges in argparse; frame indices and ``--k`` against the
loaded motion; ``--steps``, ``--length`` and the trial's frames against the
memory budget ``--memory-budget-gib``, see :mod:`animsynth.limits`). A bad
argument or input file prints one line naming the argument or the file and
line, exits with status 2 and writes nothing. ``--fps`` is the frame rate of
the input motion (1/60 to 100,000 fps): it is written to BVH output, and GIFs
play in real time at it.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys

import numpy as np

from .cli_inputs import (UsageError, _check_per_file_options, _existing_dir, _existing_file, _finite, _inputs,
                         _load, _load_any, _load_bvh, _out_with, _split_motion_args, fps_float, index_int,
                         positive_float, positive_int, seed_int)
from .limits import DEFAULT_MEMORY_BUDGET_GIB, check_budget
from .pace import pace, pace_warning

MOTION_OUTPUTS = (".bvh", ".amc", ".gif")
#: GIF frames of ``animsynth preview``: 20 s in real time at 30 GIF frames per second; a longer clip plays
#: faster, evenly subsampled, the speed-up in its title (see :func:`animsynth.viz.skeleton_gif`).
PREVIEW_MAX_FRAMES = 600


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``animsynth CMD: error: argument --x: ...``."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _labels(text: str) -> str:
    from .io.ckplus import EMOTIONS

    parts = text.split(",")
    if not text.strip() or any(not p.strip() for p in parts):
        raise argparse.ArgumentTypeError(f"expected comma-separated labels such as fear,surprise,happy, got {text!r}")
    unknown = [p.strip() for p in parts if p.strip() not in EMOTIONS[1:]]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown CK+ emotion {unknown[0]!r} (one of {', '.join(EMOTIONS[1:])})")
    return text


def cmd_amc2bvh(a) -> None:
    from .io.bvh import write_bvh

    m = _load(a.asf, a.amc, a.fps)
    write_bvh(a.out, m, scale=m.skeleton.length_to_m if a.metres else 1.0)
    print(f"wrote {a.out}: {m.n_frames} frames, {len(m.skeleton.joints)} joints")


def cmd_preview(a) -> None:
    from .viz import motion_previews

    files, a.out = _split_motion_args(a.files, None, (".gif",))
    m, src = _load_any(a, files)
    _check_frames(a, m.n_frames, len(m.skeleton.joints), "frames of " + src)
    # titled by the input file; plays in real time, or a long clip evenly subsampled with its speed-up stated
    motion_previews(m, gif_path=a.out, titles=[os.path.basename(src)], max_frames=PREVIEW_MAX_FRAMES)
    from .axes import standing_height

    height = standing_height(m.skeleton, m.values) * float(m.skeleton.length_to_m)
    print(f"wrote {a.out}: {src} stands {height:.3g} m tall (median over frames along its up axis; check "
          "--length-to-m if that is not the body's height)")


def cmd_generate(a) -> None:
    from .io import read_amc, read_asf
    from .retarget import continuous_clips
    from .motion import Motion
    from .simplicial import generate_from_trials

    a.train, a.out = _split_motion_args(a.train, a.out, MOTION_OUTPUTS)
    if a.start_trial >= len(a.train):
        raise UsageError("--start-trial", f"{a.start_trial} but only {len(a.train)} training file(s) given (0-based)")
    bvh = [p.lower().endswith(".bvh") for p in a.train]
    if any(bvh) and not all(bvh):
        raise UsageError("train", "give .bvh files or .amc files (with --asf), not both")
    if all(bvh):
        from .retarget import retarget

        train = [_load_bvh(a, p) for p in a.train]
        sk = train[0].skeleton
        # one skeleton: the first file's (other channels or rest frames read onto it, other rest offsets
        # retargeted with a warning, other joints or rest poses refused naming both files)
        train = [train[0]] + [retarget(m, sk, p, a.train[0]) for p, m in zip(a.train[1:], train[1:])]
    else:
        if a.asf is None:
            raise UsageError("--asf", "training .amc files need the skeleton: --asf SKEL.asf")
        sk = read_asf(a.asf)
    n_angles = sk.n_dof - len(sk.joints[0].dofs)
    if a.latent_dim > n_angles:
        raise UsageError("--latent-dim", f"{a.latent_dim} exceeds the {n_angles} joint angles of "
                                         f"{a.train[0] if all(bvh) else a.asf}")
    # output values, joint angles, latent path and the GIF's joint positions, float64
    check_budget(f"argument --steps: {a.steps} steps",
                 8.0 * (a.steps + 1) * (2 * sk.n_dof + a.latent_dim + 3 * len(sk.joints)), a.memory_budget_gib)
    if not all(bvh):
        train = [read_amc(p, sk, fps=a.fps) for p in a.train]
    # each file's angles continuous along time, on the branch of the first file's (the start pose too)
    train = continuous_clips(train)
    n_start = train[a.start_trial].n_frames
    if a.start_frame >= n_start:
        raise UsageError("--start-frame", f"{a.start_frame} is outside {a.train[a.start_trial]} ({n_start} frames, 0-based)")
    n_root = len(sk.joints[0].dofs)
    first = train[a.start_trial].values[a.start_frame]  # a frame of the file, whatever --rate
    train = _at_rate(train, a.rate, a.train)
    n_train = sum(m.n_frames for m in train)
    if a.k > n_train:
        raise UsageError("--k", f"{a.k} neighbours but the training files hold only {n_train} frames")
    if a.latent_dim > train[0].without_root().shape[1]:
        raise UsageError("--latent-dim", f"{a.latent_dim} exceeds the {train[0].without_root().shape[1]} joint angles")
    start = first[n_root:] if a.start_pose is None else None
    angles, info = generate_from_trials(
        [m.without_root() for m in train], method=a.method, k=a.k, latent_dim=a.latent_dim,
        steps=a.steps, start=start, seed=a.seed)
    values = np.zeros((angles.shape[0], sk.n_dof))
    values[:, n_root:] = angles
    values[:, :n_root] = first[:n_root]  # root held at the start pose
    out = Motion(values, sk, train[0].fps, "generated")
    moved = pace(out, train)
    line = pace_warning(moved, _pace_helps(a, train[0].fps, float(train[0].meta.get("file_fps", train[0].fps))))
    if line:
        print(f"animsynth generate: warning: {line}", file=sys.stderr)
    _write_motion(a.out, out)
    print(f"wrote {a.out}: {angles.shape[0]} frames at {out.fps:g} fps ({info}; {moved.ratio:.2g} of the "
          "capture's pace)")


def _at_rate(clips: list, rate: float | None, names: list[str]) -> list:
    """``clips`` at ``rate`` fps (``--rate``): every n-th frame, n = the files' rate / ``rate`` (a whole number);
    unchanged without ``--rate``. ``meta["file_fps"]`` keeps the files' own rate."""
    from .motion import Motion

    fps = float(clips[0].fps)
    if rate is None or abs(rate - fps) < 1e-9:
        return [Motion(c.values, c.skeleton, c.fps, c.name, dict(c.meta, file_fps=fps)) for c in clips]
    n = fps / rate
    if abs(n - round(n)) > 1e-6 or round(n) < 1:
        fits = [f"{fps / k:g}" for k in range(1, 9) if abs(fps / k - round(fps / k)) < 1e-9][:5]
        raise UsageError("--rate", f"{rate:g} fps is not the rate of {names[0]} ({fps:g} fps) divided by a whole "
                                   f"number; use one of {', '.join(fits)}")
    return [Motion(c.values[::int(round(n))], c.skeleton, rate, c.name, dict(c.meta, file_fps=fps)) for c in clips]


def _pace_helps(a, fps: float, file_fps: float) -> list[str]:
    """What helps a field follower that stops or slows: a larger latent space, a lower rate, another method."""
    helps = [f"--latent-dim {a.latent_dim + 1} or more (in a low-dimensional latent space the interpolated "
             "vectors often cancel)"]
    if fps > 30 and abs(file_fps / 30 - round(file_fps / 30)) < 1e-9:
        helps.append(f"--rate 30 (every {round(file_fps / 30)}th frame of the {file_fps:g} fps files: each step "
                     "then covers more motion; Gauch & Peters fitted every 120 fps frame, docs/cli.md)")
    helps.append(f"--method {'knn' if a.method == 'delaunay' else 'delaunay'}, or a method that plays captured "
                 "frames (animsynth resequence; the comparison's motion graph and motion matching)")
    return helps


def cmd_resequence(a) -> None:
    from .retarget import unwrap_angles
    from .resequencing.quick import resequence_motion

    files, a.out = _split_motion_args(a.files, a.out, MOTION_OUTPUTS)
    m, a.amc = _load_any(a, files)
    m = unwrap_angles(m, a.amc)  # a BVH file is already (load_trial); an AMC file here
    if a.length is not None:
        # played values, local rotations (quaternions) and joint positions of every frame, float64
        check_budget(f"argument --length: {a.length} frames",
                     8.0 * a.length * (2 * m.skeleton.n_dof + 7 * len(m.skeleton.joints)), a.memory_budget_gib)
    # frame distance, neighbourhood and geodesic matrices of the trial
    check_budget(f"{a.amc}: {m.n_frames} frames", 8.0 * 4 * m.n_frames ** 2, a.memory_budget_gib)
    for option, value in (("--start", a.start), ("--end", a.end)):
        if value >= m.n_frames:
            raise UsageError(option, f"{value} is outside {a.amc} ({m.n_frames} frames, 0-based)")
    if a.k is not None and a.k >= m.n_frames:
        raise UsageError("--k", f"{a.k} neighbours but {a.amc} has only {m.n_frames} frames")
    frames, played = resequence_motion(m, a.start, a.end, method=a.method, metric=a.metric, k=a.k,
                                       global_dof=a.global_dof, length=a.length)
    _write_motion(a.out, played)
    print(f"wrote {a.out}: {len(frames)} frames; path " + " ".join(map(str, frames[:20])) + (" ..." if len(frames) > 20 else ""))


def _check_frames(a, n_frames: int, n_joints: int, what: str) -> None:
    check_budget(f"{what}: {n_frames}", 8.0 * n_frames * n_joints * 6, a.memory_budget_gib)


def cmd_face(a) -> None:
    from .facegraph.quick import synthesise_from_labels

    out = synthesise_from_labels(a.labels.split(","), a.out, ckplus_dir=a.ckplus, seed=a.seed)
    print(f"wrote {a.out} ({out})")


def _project_file(rel: str) -> str:
    """A file of the project folder (``config/...``): beside the installed sources (``pip install -e``), else
    in the working directory."""
    from pathlib import Path

    for root in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (root / rel).is_file():
            return str(root / rel)
    raise UsageError("--config", f"the project's {rel} is not beside the animsynth sources nor in the working "
                                 "directory; run from the project folder")


def _compare_settings(configs) -> dict:
    """The ``compare`` block a run with ``--configfile`` ``configs`` would use: config/config.yaml, then each
    file merged over it in order (as Snakemake merges them), validated by config/schema.yaml (which fills every
    default)."""
    import yaml
    from snakemake.utils import update_config

    from .config import ConfigError, validate_config

    cfg: dict = {}
    for path in [_project_file("config/config.yaml")] + list(configs or []):
        with open(path, encoding="utf-8") as fh:
            try:
                data = yaml.safe_load(fh) or {}
            except yaml.YAMLError as exc:
                raise UsageError("--config", f"{path}: not YAML ({' '.join(str(exc).split())})") from None
        if not isinstance(data, dict):
            raise UsageError("--config", f"{path}: expected a mapping of config keys")
        update_config(cfg, data)
    try:
        validate_config(cfg, _project_file("config/schema.yaml"))
    except ConfigError as exc:
        raise UsageError("--config", " ".join(str(exc).split())) from None
    return cfg["compare"]


def cmd_score(a) -> None:
    """Score BVH files against the held-out capture with the compare family's metrics
    (:func:`animsynth.compare.scoring.score_motions`)."""
    from .compare.scoring import score_motions
    from .tables import write_table

    for f in a.generated:
        if not f.lower().endswith(".bvh"):
            raise UsageError("GENERATED", f"expected .bvh files, got {f!r}")
        if not os.path.isfile(f):
            raise UsageError("GENERATED", f"no such file {f!r}")
    for f in a.database or []:
        if not f.lower().endswith(".bvh"):
            raise UsageError("--database", f"expected .bvh files, got {f!r}")
    cmp = _compare_settings(a.config)
    mcfg = dict(cmp["metrics"])
    if a.floor_m is not None:
        mcfg["floor_m"] = a.floor_m
    context = int(cmp["context"]) if a.context is None else a.context
    motions = {}
    for f in dict.fromkeys([a.reference] + a.generated + list(a.database or [])):
        motions[f] = _load_bvh(a, f)
        _check_frames(a, motions[f].n_frames, len(motions[f].skeleton.joints), "frames of " + f)
    ref = motions[a.reference]
    generated = {f: motions[f] for f in a.generated}
    database = {f: motions[f] for f in a.database} if a.database else None
    table = score_motions(generated, ref, database, context, mcfg, reference_name=a.reference)
    write_table(table, a.out, md=False)
    print(f"wrote {a.out}: {len(table)} scored file(s) against {a.reference}, {context} start frames"
          + ("" if database else "; no --database: the metrics that read it are empty"))


def _write_motion(path: str, motion) -> None:
    kind = path.lower()  # the same rule as the --out check (OUT.BVH is a BVH file)
    if kind.endswith(".bvh"):
        from .io.bvh import write_bvh

        write_bvh(path, motion)
    elif kind.endswith(".amc"):
        from .io.amc import write_amc

        write_amc(path, motion)
    elif kind.endswith(".gif"):
        from .viz import motion_previews

        motion_previews(motion, gif_path=path)
    else:
        raise ValueError(f"output {path!r}: use a .bvh, .amc or .gif file name")


def build_parser() -> argparse.ArgumentParser:
    """The ``animsynth`` command line: a subcommand per task, each with its own options; every one
    that reads BVH takes the BVH input options, and every one the memory budget."""
    p = _Parser(prog="animsynth", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    for add in (_add_amc2bvh, _add_preview, _add_generate, _add_resequence, _add_face, _add_score):
        add(sub)
    for name in ("preview", "generate", "resequence", "score"):
        _add_bvh_input_options(sub.choices[name])
    for s in sub.choices.values():
        s.add_argument("--memory-budget-gib", type=positive_float, default=DEFAULT_MEMORY_BUDGET_GIB,
                       help=f"refuse requests whose arrays exceed this many GiB (default {DEFAULT_MEMORY_BUDGET_GIB:g})")
    return p


def _add_amc2bvh(sub) -> None:
    """The ``amc2bvh`` command: an ASF/AMC trial written as BVH."""
    s = sub.add_parser("amc2bvh", help="convert an ASF/AMC trial to BVH (opens in Blender)")
    s.add_argument("asf", type=_existing_file), s.add_argument("amc", type=_existing_file)
    s.add_argument("out", type=_out_with((".bvh",)), help="output .bvh")
    s.add_argument("--fps", type=fps_float, default=120.0, help="frame rate of the AMC motion (default 120)")
    s.add_argument("--metres", action="store_true", help="write lengths in metres instead of ASF units")
    s.set_defaults(func=cmd_amc2bvh)


def _add_preview(sub) -> None:
    """The ``preview`` command: an animated GIF of a trial's skeleton."""
    s = sub.add_parser("preview", help="animated GIF of a trial's skeleton (BVH, or ASF + AMC)")
    s.add_argument("files", nargs="+", metavar="FILE", help="MOTION.bvh, or SKEL.asf MOTION.amc; then OUT.gif")
    s.add_argument("--fps", type=fps_float, default=120.0, help="frame rate of the AMC motion (default 120)")
    s.set_defaults(func=cmd_preview)


def _add_generate(sub) -> None:
    """The ``generate`` command: a motion from Gauch & Peters' vector field (Delaunay or k-NN)."""
    s = sub.add_parser("generate", help="generate a motion with the Delaunay or k-NN vector field (Gauch & Peters)")
    s.add_argument("train", nargs="+", metavar="FILE",
                   help="training .bvh files, or .amc files with --asf (same skeleton); then OUT (or --out)")
    s.add_argument("--asf", default=None, type=_existing_file, help="the skeleton of training .amc files")
    s.add_argument("--method", choices=["delaunay", "knn"], default="delaunay")
    s.add_argument("--k", type=positive_int, default=16, help="neighbours for k-NN (and the Delaunay fallback)")
    s.add_argument("--latent-dim", type=positive_int, default=2)
    s.add_argument("--steps", type=positive_int, default=300)
    s.add_argument("--start-trial", type=index_int, default=0, help="index of the training file holding the start frame")
    s.add_argument("--start-frame", type=index_int, default=0)
    s.add_argument("--start-pose", default=None, help=argparse.SUPPRESS)
    s.add_argument("--seed", type=seed_int, default=0)
    s.add_argument("--fps", type=fps_float, default=120.0, help="frame rate of the AMC motion (default 120)")
    s.add_argument("--rate", type=fps_float, default=None,
                   help="fit and generate at this rate: every n-th frame of the files, n = their rate / RATE (a "
                        "whole number; default: every frame, as Gauch & Peters fitted CMU's 120 fps frames)")
    s.add_argument("--out", default=None, type=_out_with(MOTION_OUTPUTS), help="output .bvh, .amc or .gif")
    s.set_defaults(func=cmd_generate)


def _add_resequence(sub) -> None:
    """The ``resequence`` command: a trial's frames re-sequenced between two frames (Isomap, ST-Isomap)."""
    s = sub.add_parser("resequence", help="re-sequence a trial between two frames (Isomap / ST-Isomap + Dijkstra)")
    s.add_argument("files", nargs="+", metavar="FILE",
                   help="MOTION.bvh, or SKEL.asf MOTION.amc; then OUT (or --out)")
    s.add_argument("--start", type=index_int, required=True, help="first frame (0-based)")
    s.add_argument("--end", type=index_int, required=True, help="last frame (0-based)")
    s.add_argument("--method", choices=["isomap", "st-isomap"], default="st-isomap")
    s.add_argument("--metric", choices=["l2", "lee"], default="l2")
    s.add_argument("--k", type=positive_int, default=None, help="neighbours (default: smallest k giving one component)")
    s.add_argument("--global-dof", action="store_true", help="include root translation and orientation")
    s.add_argument("--length", type=positive_int, default=None, help="pad the path to this many frames")
    s.add_argument("--fps", type=fps_float, default=120.0, help="frame rate of the AMC motion (default 120)")
    s.add_argument("--out", default=None, type=_out_with(MOTION_OUTPUTS), help="output .bvh, .amc or .gif")
    s.set_defaults(func=cmd_resequence)


def _add_face(sub) -> None:
    """The ``face`` command: a face animation (68 landmarks) from expression labels."""
    s = sub.add_parser("face", help="synthesise a face animation (68 landmarks) from expression labels")
    s.add_argument("--labels", required=True, type=_labels, help="comma-separated, e.g. fear,surprise,happy")
    s.add_argument("--ckplus", default=None, type=_existing_dir,
                   help="CK+ root folder (default: a synthetic CK+-layout database)")
    s.add_argument("--seed", type=seed_int, default=0)
    s.add_argument("out", type=_out_with((".gif", ".csv")), help="output .gif (or .csv of landmarks)")
    s.set_defaults(func=cmd_face)


def _add_score(sub) -> None:
    """The ``score`` command: BVH files from any tool scored with the compare family's metrics."""
    s = sub.add_parser("score", help="score BVH files from any tool with the compare family's metrics",
                       description="Score generated BVH files against the held-out capture they continue, with the "
                       "metrics of compare/metrics.csv (docs/compare/own_generator.md, Score motions made anywhere). The first "
                       "--context frames of every file are the start; the frames after it are scored against the "
                       "reference's. The generator's seams, transitions and seed spread are not in a BVH file: "
                       "those columns stay empty, as do the metrics that read the database without --database.")
    s.add_argument("generated", nargs="+", metavar="GENERATED.bvh", help="generated motions (one row each)")
    s.add_argument("--reference", required=True, type=_existing_file, metavar="HELD_OUT.bvh",
                   help="the held-out capture: the start, then the frames the generated ones are compared with")
    s.add_argument("--database", nargs="+", action="extend", type=_existing_file, metavar="DB.bvh",
                   help="the clips the generator learned from (floor, L2P statistics, coverage, novelty)")
    s.add_argument("--out", required=True, type=_out_with((".csv",)), help="output .csv (columns of compare/metrics.csv)")
    s.add_argument("--context", type=positive_int, default=None,
                   help="start frames at the head of every file (default: compare.context of the config)")
    s.add_argument("--config", action="append", type=_existing_file, metavar="CONFIG.yaml",
                   help="config file(s) merged over config/config.yaml, as --configfile of a run: compare.metrics "
                        "and compare.context are read from it (default: the project's defaults)")
    s.add_argument("--floor-m", type=_finite, default=None,
                   help="floor height in metres (default: compare.metrics.floor_m, else from the database's feet)")
    s.set_defaults(func=cmd_score)


def _add_bvh_input_options(s) -> None:
    """The options of a command that reads BVH input: per-file length unit, joint roles, axes and root."""
    s.add_argument("--length-to-m", action="append", metavar="[FILE=]M",
                   help="metres per length unit of BVH input (default 1; 0.01 centimetres, 0.05644 cgspeed's CMU "
                        "conversions); FILE=M for one file; repeatable")
    s.add_argument("--role", action="append", metavar="[FILE:]ROLE=JOINT",
                   help="joint role of BVH input (e.g. left_hip=Bip01_L_Thigh); repeatable")
    s.add_argument("--up-axis", action="append", metavar="[FILE=]AXIS",
                   help="up axis of BVH input (+x -x +y -y +z -z; default: detected); a negative axis works "
                        "either way: --up-axis -z or --up-axis=-z")
    s.add_argument("--forward-axis", action="append", metavar="[FILE=]AXIS",
                   help="forward axis of BVH input (default: the smallest turn taking up to +y); a negative "
                        "axis works either way: --forward-axis -y or --forward-axis=-y")
    s.add_argument("--root", action="append", metavar="[FILE=]NAME",
                   help="the skeleton to read from a BVH file that holds several (two characters, a "
                        "character and a prop): the name of its root joint")


#: The option whose size a command's arrays grow with (named when memory runs out anyway).
SIZE_OPTIONS = {"generate": "--steps", "resequence": "--length"}


def _check_out_is_not_an_input(a) -> None:
    """Refuse an output that is one of the command's input files (it would be replaced)."""
    out = getattr(a, "out", None)
    if not out or not os.path.exists(out):
        return
    for inp in _inputs(a):
        if inp and os.path.exists(inp) and os.path.samefile(inp, out):
            option = "--out" if a.command in ("generate", "resequence", "score") else "out"
            raise UsageError(option, f"{out!r} is the input file {inp!r}; writing it would replace the input")


def _out_of_memory(a) -> str:
    option = SIZE_OPTIONS.get(a.command)
    if option and getattr(a, option[2:].replace("-", "_"), None) is not None:
        return (f"argument {option}: out of memory for {option} {getattr(a, option[2:].replace('-', '_'))} "
                f"(the machine gives less than the --memory-budget-gib {a.memory_budget_gib:g} GiB budget "
                f"allowed); lower {option} or --memory-budget-gib")
    return (f"out of memory reading or processing the input (the machine gives less than the "
            f"--memory-budget-gib {a.memory_budget_gib:g} GiB budget allowed); lower --memory-budget-gib "
            "to be told which input is too large")


#: The options whose value may be a negative axis (``-y``), which argparse would take for an option.
AXIS_OPTIONS = ("--up-axis", "--forward-axis")


def _negative_axes_joined(argv: list[str]) -> list[str]:
    """``argv`` with ``--forward-axis -y`` written ``--forward-axis=-y`` (argparse reads a value starting with
    ``-`` as an option, and ``-y`` is not a number)."""
    out, i = [], 0
    while i < len(argv):
        if argv[i] in AXIS_OPTIONS and i + 1 < len(argv) and argv[i + 1].lower() in ("-x", "-y", "-z"):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def main(argv=None) -> int:
    """Run one command; return the exit status (0 ok, 2 bad argument or input)."""
    parser = build_parser()
    argv = _negative_axes_joined(list(sys.argv[1:] if argv is None else argv))
    try:
        # files may come after options too (resequence walk.bvh --start 10 --end 300 out.bvh): argparse leaves
        # the ones after an option over; they join the command's file list
        args, extra = parser.parse_known_args(argv)
        listed = next((k for k in ("files", "train", "generated") if hasattr(args, k)), None)
        if extra and (listed is None or any(e.startswith("-") for e in extra)):
            parser.error(f"unrecognized arguments: {' '.join(extra)}")
        if extra:
            setattr(args, listed, getattr(args, listed) + extra)
    except SystemExit as exc:  # argparse: --help (0) or a bad argument (2, message printed)
        return int(exc.code or 0)
    logging.basicConfig(level=logging.WARNING, format="animsynth: %(levelname)s: %(message)s")
    try:
        _check_out_is_not_an_input(args)
        _check_per_file_options(args)
        args.func(args)
    except MemoryError:  # numpy's _ArrayMemoryError too: a budget above what the machine has
        print(f"animsynth {args.command}: error: {_out_of_memory(args)}", file=sys.stderr)
        return 2
    except RecursionError:
        print(f"animsynth {args.command}: error: {', '.join(_inputs(args)) or 'the input'}: "
              "nested too deeply to process", file=sys.stderr)
        return 2
    except (ValueError, KeyError, IndexError, OSError, ImportError, RuntimeError) as exc:
        # UsageError names the argument; MotionFormatError names file and line
        msg = " ".join(str(exc).split()) or type(exc).__name__  # one line
        print(f"animsynth {args.command}: error: {msg}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
