"""Does a generated motion move like the capture it was made from? Frames where it stands still, and its pace.

A generator can write a file of the right length that hardly moves: a vector field followed in a 2-D latent
space settles into a point where the interpolated vectors cancel (a LAFAN1 take gave 102 still frames of 118
through ``animsynth generate``), and on CMU's 120 fps walks the field moves at a tenth of the capture's pace.
:func:`pace` measures it and :func:`pace_warning` says it in one line with what helps, before a command calls
the result a success.

The measure is the pose alone (the root's DOF held at zero: the command line holds the root at the start pose):
per frame, the largest step of any joint in metres. A frame whose step is below :data:`STILL_FRACTION` of the
capture's median step is still; the pace is the median step over the capture's median step, at the same frame
rate (the capture as the generator was fitted on it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import forward_kinematics
from .motion import Motion

__all__ = ["STILL_FRACTION", "STILL_SHARE", "SLOW_PACE", "Pace", "pose_steps", "pace", "pace_warning"]

#: a frame whose largest joint step is below this share of the capture's median step stands still
STILL_FRACTION = 0.1
#: a motion with at least this share of still frames is warned ("stops moving")
STILL_SHARE = 0.25
#: a motion whose median step is below this share of the capture's is warned ("far below the capture's pace"):
#: Gauch & Peters' training vectors, (x[i+1] - x[i]) / 2, move half a frame per step by construction, so half the
#: capture's pace is the method's own; a quarter is half of that
SLOW_PACE = 0.25


def pose_steps(motion: Motion) -> np.ndarray:
    """``(frames - 1,)``: per frame, the largest distance in metres any joint moved since the frame before, with
    the root's DOF at zero (the pose alone)."""
    sk = motion.skeleton
    values = np.array(motion.values, float)
    values[:, :len(sk.joints[0].dofs)] = 0.0
    if len(values) < 2:
        return np.zeros(0)
    p = forward_kinematics(sk, values) * float(sk.length_to_m)
    return np.linalg.norm(np.diff(p, axis=0), axis=2).max(axis=1)


@dataclass(frozen=True)
class Pace:
    """How a generated motion moves against its capture (steps in metres per frame)."""

    frames: int
    still_frames: int
    largest_step_m: float
    median_step_m: float
    capture_step_m: float

    @property
    def ratio(self) -> float:
        """The generated median step over the capture's (1: the capture's pace; nan: a still capture)."""
        return self.median_step_m / self.capture_step_m if self.capture_step_m > 0 else float("nan")


def pace(generated: Motion, captures: list[Motion]) -> Pace:
    """The :class:`Pace` of ``generated`` against ``captures`` (the clips it was made from, at its frame rate)."""
    steps = pose_steps(generated)
    cap = np.concatenate([pose_steps(c) for c in captures] or [np.zeros(0)])
    cap_step = float(np.median(cap)) if cap.size else 0.0
    still = int(np.sum(steps < STILL_FRACTION * cap_step)) if cap_step > 0 else 0
    return Pace(int(len(steps)), still, float(steps.max(initial=0.0)),
                float(np.median(steps)) if steps.size else 0.0, cap_step)


def pace_warning(p: Pace, helps: list[str]) -> str | None:
    """One line when the motion stops moving (:data:`STILL_SHARE` of its frames still) or moves far below the
    capture's pace (:data:`SLOW_PACE`), naming the numbers and ``helps`` (what to try); None otherwise."""
    if not p.frames or not p.capture_step_m > 0:
        return None
    still = p.still_frames >= STILL_SHARE * p.frames
    slow = p.ratio < SLOW_PACE
    if not (still or slow):
        return None
    what = []
    if still:
        what.append(f"stands still in {p.still_frames} of its {p.frames} steps (a step under "
                    f"{STILL_FRACTION:g} of the capture's median; its largest step {_length(p.largest_step_m)})")
    what.append(f"moves at {p.ratio:.2g} of the capture's pace (median step {_length(p.median_step_m)}, the "
                f"capture's {_length(p.capture_step_m)})")
    return "the generated motion " + " and ".join(what) + "; what helps: " + "; ".join(helps)


def _length(m: float) -> str:
    return f"{m * 100:.2g} cm" if m >= 0.01 else f"{m * 1000:.2g} mm"
