"""compare: foot skating of motion matching with and without the reference's foot locking, on the paper run's clips.

A measurement, not a timed test: the paper run's comparison clips built as its ``compare_clips`` rule builds them
(:func:`animsynth.compare.protocol.prepare_clips` with ``config/config.yaml``'s ``compare`` block under
``config/cmu.yaml``'s and ``config/paper.yaml``'s: the Table I subsets w1 w2 r1 r2 left one out, the
re-sequencing clips walk / run / dance with their end held out; 30 fps, 8 start frames, 60 generated), the
trials read from ``../shared/data/cmu_mocap`` (``ANIMSYNTH_SHARED_DATA`` overrides ``../shared/data``). Every
clip is scored by :func:`animsynth.compare.scoring.score` (the family's metrics: ``skate_share`` over the start's
last frame and the generated ones, the database's floor, contact below 0.05 m, skating above 0.5 m/s).

Rows: ``motion_matching`` (the reference's defaults: foot locking and leg IK on), ``motion_matching_no_lock``
(``make_motion_matching(..., foot_lock=False)``), ``motion_graph`` and ``replay`` (the compare family's own,
:func:`animsynth.compare.generators.registry.make_generator`). Motion matching is deterministic, so one seed per clip;
the motion graph gets the run's 5 seeds. Per clip the seeds' mean; printed: the mean, median and pooled values
over clips, how many clips motion matching skates less than the motion graph on, and the CPU per sample
(``time.process_time``, one BLAS thread; motion matching's first call, before its rollout is kept), and for
motion matching the contact and skating foot-joint frames split by what the foot locking did (locked; labelled in
contact but not locked; labelled moving) and how near its locked feet come to their locks.

Run: ``python benchmarks/skating_compare_modern.py [out.csv]`` (a few minutes of one core).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from threadpoolctl import threadpool_limits

from animsynth.compare import protocol, scoring
from animsynth.config import trial_records
from animsynth.compare.generators.registry import make_generator
from animsynth.compare.generators.motionmatching import make_motion_matching
from animsynth.io import read_amc, read_asf

REPO = Path(__file__).resolve().parents[1]
CMU = Path(os.environ.get("ANIMSYNTH_SHARED_DATA", REPO.parent / "shared" / "data")) / "cmu_mocap"


def _config() -> tuple[dict, dict, dict, dict]:
    """The compare block (the paper run's layers), subsets, re-sequencing trials, trials by id; the master seed
    in the block's ``master_seed``."""
    base = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cmu = yaml.safe_load((REPO / "config" / "cmu.yaml").read_text())
    paper = yaml.safe_load((REPO / "config" / "paper.yaml").read_text())
    cfg = dict(base["compare"])
    for layer in (cmu.get("compare", {}), paper.get("compare", {})):
        cfg.update({k: v for k, v in layer.items() if k not in ("subsets", "resequencing")})
    cfg["master_seed"] = int(paper.get("seed", cmu.get("seed", base["seed"])))
    trials = {t["id"]: t for t in trial_records(cmu["trials"])}
    return cfg, dict(cmu["subsets"]), dict(cmu["resequencing_trials"]), trials


def clips() -> tuple[list, dict]:
    cfg, subsets, reseq, trials = _config()
    ids = list(dict.fromkeys([t for v in subsets.values() for t in v] + list(reseq.values())))
    motions = {}
    for i in ids:
        m = read_amc(CMU / trials[i]["amc"], read_asf(CMU / trials[i]["asf"]))
        m.name = i
        motions[i] = m
    return protocol.prepare_clips(motions, subsets, reseq, cfg), cfg


def _by_lock(clip, ref, motion, mcfg) -> dict:
    """Contact and skating foot-joint frames of the generated motion (as ``foot_skating`` counts them) split by
    what the foot locking did to their foot: ``locked`` (the target is a locked point), ``label`` (the played
    database frame is labelled in contact but the foot is not locked: released or not yet) and ``moving``
    (labelled out of contact, so never locked). Empty for a motion without foot locking."""
    if "contact_locked" not in motion.meta:
        return {}
    from animsynth.compare import measures as M
    from animsynth.motion import Motion

    joined = Motion(np.vstack([clip.start.values[-1:], motion.values]), motion.skeleton, motion.fps)
    P = M.positions(joined)[:, ref.foot_idx]
    step = np.linalg.norm(np.diff(P[:, :, [0, 2]], axis=0), axis=-1) * motion.fps
    contact = (P[1:, :, 1] - ref.floor) < float(mcfg["contact_height_m"])
    skate = contact & (step > float(mcfg["skate_speed_m_s"]))
    foot = np.array([0, 0, 1, 1])  # FOOT_ROLES: left ankle, left toe, right ankle, right toe
    locked = motion.meta["contact_locked"][:, foot]
    label = motion.meta["contact_states"][:, foot] & ~locked
    moving = ~motion.meta["contact_states"][:, foot]
    from animsynth.compare.generators.footlock import contact_points, hip_knee_ankle

    sk = motion.skeleton
    miss = np.linalg.norm(contact_points(sk, motion.values, hip_knee_ankle(sk)) - motion.meta["contact_targets"], axis=-1)
    miss = miss[motion.meta["contact_locked"]]
    out = {"locked_frames": int(miss.size), "lock_miss_mm_sum": 1000 * float(miss.sum()),
           "lock_miss_under_1mm": int((miss < 0.001).sum())}
    for name, sel in (("locked", locked), ("label", label), ("moving", moving)):
        out[f"contact_{name}"] = int((contact & sel).sum())
        out[f"skate_{name}"] = int((skate & sel).sum())
    return out


def run(out: str | None = None) -> pd.DataFrame:
    with threadpool_limits(limits=1, user_api="blas"):
        cl, cfg = clips()
        mcfg = cfg["metrics"]
        rows = []
        for clip in cl:
            ref = scoring.reference(clip, mcfg)
            gens = {"motion_matching": (make_motion_matching({}), 1),
                    "motion_matching_no_lock": (make_motion_matching({}, foot_lock=False,
                                                                     name="motion_matching_no_lock"), 1),
                    "motion_graph": (make_generator("motion_graph", cfg), int(cfg["seeds"])),
                    "replay": (make_generator("replay", cfg, held_out=clip.held_out), 1)}
            for name, (gen, n_seeds) in gens.items():
                gen.fit(clip.database)
                seeds = protocol.clip_seeds(cfg["master_seed"], cfg["seed"], clip.clip, n_seeds)
                for i, s in enumerate(seeds):
                    c0 = time.process_time()
                    m = gen.generate(clip.start, clip.length, s)
                    cpu = time.process_time() - c0
                    row, _ = scoring.score(clip, ref, m, name, mcfg)
                    rows.append({"clip": clip.clip, "group": clip.group, "generator": name, "seed": i,
                                 "skate_share": row["skate_share"], "contact_share": row["contact_share"],
                                 "transition_skate_share": row["transition_skate_share"],
                                 "skate_m_per_contact_frame": row["skate_m_per_contact_frame"],
                                 "n_seams": row["n_seams"], "sample_cpu_ms": 1000 * cpu, **_by_lock(clip, ref, m, mcfg)})
    df = pd.DataFrame(rows)
    if out:
        df.to_csv(out, index=False)
    return df


def summary(df: pd.DataFrame) -> str:
    per = df.groupby(["generator", "clip"]).mean(numeric_only=True).reset_index()
    lines = []
    for g, d in per.groupby("generator", sort=False):
        pooled = (d.skate_share * d.contact_share).sum() / d.contact_share.sum()
        lines.append(f"{g:26s} clips {len(d):2d}  skate share mean {d.skate_share.mean():.3f} median "
                     f"{d.skate_share.median():.3f} (contact-weighted {pooled:.3f}); contact share "
                     f"{d.contact_share.mean():.3f}; skate m/contact frame {d.skate_m_per_contact_frame.mean():.4f}; "
                     f"seams {d.n_seams.mean():.1f}; CPU/sample median {d.sample_cpu_ms.median():.1f} ms "
                     f"(mean {d.sample_cpu_ms.mean():.1f})")
    mm = df[df.generator == "motion_matching"]
    if "contact_locked" in mm:
        parts = [f"{k}: {int(mm[f'skate_{k}'].sum())} of {int(mm[f'contact_{k}'].sum())} contact joint-frames skate "
                 f"({mm[f'skate_{k}'].sum() / max(mm[f'contact_{k}'].sum(), 1):.2f})" for k in ("locked", "label", "moving")]
        lines.append("motion_matching by foot state: " + "; ".join(parts))
        n = max(int(mm.locked_frames.sum()), 1)
        lines.append(f"motion_matching locked foot-frames {int(mm.locked_frames.sum())}: contact point within 1 mm of "
                     f"its lock on {mm.lock_miss_under_1mm.sum() / n:.2f}, mean miss {mm.lock_miss_mm_sum.sum() / n:.1f} mm")
    w = per.pivot(index="clip", columns="generator", values="skate_share")
    for a in ("motion_matching", "motion_matching_no_lock"):
        less = int((w[a] < w["motion_graph"]).sum())
        lines.append(f"{a} skates less than motion_graph on {less} of {len(w)} clips")
    return "\n".join(lines)


if __name__ == "__main__":
    df = run(sys.argv[1] if len(sys.argv) > 1 else None)
    print(summary(df))
