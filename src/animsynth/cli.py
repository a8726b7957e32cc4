"""``animsynth``: one-off use of the library outside Snakemake.

    animsynth amc2bvh SKEL.asf MOTION.amc OUT.bvh
    animsynth preview SKEL.asf MOTION.amc OUT.gif
    animsynth generate --method delaunay TRAIN.amc ... --asf SKEL.asf --start-frame 0 --steps 300 OUT.bvh
    animsynth resequence SKEL.asf MOTION.amc --start 10 --end 300 OUT.bvh
    animsynth face --labels fear,surprise,happy OUT.gif

``animsynth COMMAND --help`` explains each. Errors name the file/line or
option and exit with status 2.
"""

from __future__ import annotations

import argparse
import logging
import sys

import numpy as np


def _load(asf: str, amc: str, fps: float):
    from .io import read_amc, read_asf

    return read_amc(amc, read_asf(asf), fps=fps)


def cmd_amc2bvh(a) -> None:
    from .io.bvh import write_bvh

    m = _load(a.asf, a.amc, a.fps)
    write_bvh(a.out, m, scale=m.skeleton.length_to_m if a.metres else 1.0)
    print(f"wrote {a.out}: {m.n_frames} frames, {len(m.skeleton.joints)} joints")


def cmd_preview(a) -> None:
    from .viz import motion_previews

    m = _load(a.asf, a.amc, a.fps)
    motion_previews(m, gif_path=a.out)
    print(f"wrote {a.out}")


def cmd_generate(a) -> None:
    from .io import read_amc, read_asf
    from .motion import Motion
    from .simplicial import generate_from_trials

    sk = read_asf(a.asf)
    train = [read_amc(p, sk, fps=a.fps) for p in a.train]
    start = train[a.start_trial].without_root()[a.start_frame] if a.start_pose is None else None
    angles, info = generate_from_trials(
        [m.without_root() for m in train], method=a.method, k=a.k, latent_dim=a.latent_dim,
        steps=a.steps, start=start, seed=a.seed)
    values = np.zeros((angles.shape[0], sk.n_dof))
    n_root = len(sk.joints[0].dofs)
    values[:, n_root:] = angles
    values[:, :n_root] = train[a.start_trial].values[a.start_frame, :n_root]  # root held at the start pose
    _write_motion(a.out, Motion(values, sk, a.fps, "generated"))
    print(f"wrote {a.out}: {angles.shape[0]} frames ({info})")


def cmd_resequence(a) -> None:
    from .resequencing.study import resequence_motion

    m = _load(a.asf, a.amc, a.fps)
    frames, played = resequence_motion(m, a.start, a.end, method=a.method, metric=a.metric, k=a.k,
                                       global_dof=a.global_dof, length=a.length)
    _write_motion(a.out, played)
    print(f"wrote {a.out}: {len(frames)} frames; path " + " ".join(map(str, frames[:20])) + (" ..." if len(frames) > 20 else ""))


def cmd_face(a) -> None:
    from .facegraph.quick import synthesise_from_labels

    out = synthesise_from_labels(a.labels.split(","), a.out, ckplus_dir=a.ckplus, seed=a.seed)
    print(f"wrote {a.out} ({out})")


def _write_motion(path: str, motion) -> None:
    if path.endswith(".bvh"):
        from .io.bvh import write_bvh

        write_bvh(path, motion)
    elif path.endswith(".amc"):
        from .io.amc import write_amc

        write_amc(path, motion)
    elif path.endswith(".gif"):
        from .viz import motion_previews

        motion_previews(motion, gif_path=path)
    else:
        raise ValueError(f"output {path!r}: use a .bvh, .amc or .gif file name")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="animsynth", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("amc2bvh", help="convert an ASF/AMC trial to BVH (opens in Blender)")
    s.add_argument("asf"), s.add_argument("amc"), s.add_argument("out", help="output .bvh")
    s.add_argument("--fps", type=float, default=120.0)
    s.add_argument("--metres", action="store_true", help="write lengths in metres instead of ASF units")
    s.set_defaults(func=cmd_amc2bvh)

    s = sub.add_parser("preview", help="animated GIF of an ASF/AMC trial's skeleton")
    s.add_argument("asf"), s.add_argument("amc"), s.add_argument("out", help="output .gif")
    s.add_argument("--fps", type=float, default=120.0)
    s.set_defaults(func=cmd_preview)

    s = sub.add_parser("generate", help="generate a motion with the Delaunay or k-NN vector field (Gauch & Peters)")
    s.add_argument("train", nargs="+", help="training .amc files (same skeleton)")
    s.add_argument("--asf", required=True)
    s.add_argument("--method", choices=["delaunay", "knn"], default="delaunay")
    s.add_argument("--k", type=int, default=16, help="neighbours for k-NN (and the Delaunay fallback)")
    s.add_argument("--latent-dim", type=int, default=2)
    s.add_argument("--steps", type=int, default=300)
    s.add_argument("--start-trial", type=int, default=0, help="index of the training file holding the start frame")
    s.add_argument("--start-frame", type=int, default=0)
    s.add_argument("--start-pose", default=None, help=argparse.SUPPRESS)
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--fps", type=float, default=120.0)
    s.add_argument("--out", required=True, help="output .bvh, .amc or .gif")
    s.set_defaults(func=cmd_generate)

    s = sub.add_parser("resequence", help="re-sequence a trial between two frames (Isomap / ST-Isomap + Dijkstra)")
    s.add_argument("asf"), s.add_argument("amc")
    s.add_argument("--start", type=int, required=True)
    s.add_argument("--end", type=int, required=True)
    s.add_argument("--method", choices=["isomap", "st-isomap"], default="st-isomap")
    s.add_argument("--metric", choices=["l2", "lee"], default="l2")
    s.add_argument("--k", type=int, default=None, help="neighbours (default: smallest k giving one component)")
    s.add_argument("--global-dof", action="store_true", help="include root translation and orientation")
    s.add_argument("--length", type=int, default=None, help="pad the path to this many frames")
    s.add_argument("--fps", type=float, default=120.0)
    s.add_argument("--out", required=True, help="output .bvh, .amc or .gif")
    s.set_defaults(func=cmd_resequence)

    s = sub.add_parser("face", help="synthesise a face animation (68 landmarks) from expression labels")
    s.add_argument("--labels", required=True, help="comma-separated, e.g. fear,surprise,happy")
    s.add_argument("--ckplus", default=None, help="CK+ root folder (default: a synthetic CK+-layout database)")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("out", help="output .gif (or .csv of landmarks)")
    s.set_defaults(func=cmd_face)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="animsynth: %(levelname)s: %(message)s")
    try:
        args.func(args)
    except (ValueError, KeyError, OSError, ImportError) as exc:
        print(f"animsynth {args.command}: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
