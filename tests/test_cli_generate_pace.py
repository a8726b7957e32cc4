"""``animsynth generate`` checks the motion it writes: one that stops moving, or moves far below the capture's
pace, is one warning with what helps (a larger latent space, a lower rate, another method); ``--rate`` fits at a
lower rate."""

from __future__ import annotations

import numpy as np
import pytest

from animsynth.cli import main
from animsynth.io.bvh import read_bvh, write_bvh
from animsynth.motion import Motion
from animsynth.pace import STILL_FRACTION, pace, pace_warning, pose_steps
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion


@pytest.fixture(scope="module")
def walk():
    return generate_motion("walk_straight", 120, 0, cmu_like_skeleton("p", 1))


def test_the_pace_of_a_capture_a_still_pose_and_a_slowed_copy(walk):
    assert pace(walk, [walk]).ratio == pytest.approx(1.0) and pace(walk, [walk]).still_frames < 12
    still = Motion(np.repeat(walk.values[:1], 60, axis=0), walk.skeleton, walk.fps)
    p = pace(still, [walk])
    assert (p.still_frames, p.frames, p.largest_step_m) == (59, 59, 0.0)
    # the capture played at a quarter speed: every step a quarter as long (up to the curvature between frames)
    t = np.linspace(0, 119, 477)
    slow = Motion(np.stack([np.interp(t, np.arange(120), c) for c in walk.values.T], axis=1), walk.skeleton, walk.fps)
    assert pace(slow, [walk]).ratio == pytest.approx(0.25, rel=0.1)
    assert pose_steps(walk).shape == (119,)
    # the pose alone: moving the root along the floor does not change a single step
    carried = walk.values.copy()
    carried[:, :3] += np.arange(len(carried))[:, None] * np.array([0.3, 0.0, 0.7])
    assert np.array_equal(pose_steps(Motion(carried, walk.skeleton, walk.fps)), pose_steps(walk))
    line = pace_warning(p, ["--latent-dim 3"])
    assert line.startswith("the generated motion stands still in 59 of its 59 steps (a step under "
                           f"{STILL_FRACTION:g} of the capture's median") and line.endswith("what helps: --latent-dim 3")
    assert pace_warning(pace(walk, [walk]), ["x"]) is None


def _write(tmp_path, motions):
    paths = []
    for k, m in enumerate(motions):
        paths.append(str(tmp_path / f"t{k}.bvh"))
        write_bvh(paths[-1], m)
    return paths


def test_a_field_that_freezes_is_warned_with_what_helps(tmp_path, walk, capsys):
    """A capture and the same capture played backwards: the training vectors cancel everywhere, so the field
    follower stands still from any start, in any latent dimension (a constructed case of a LAFAN1 take's 102
    still frames of 118)."""
    back = Motion(walk.values[::-1].copy(), walk.skeleton, walk.fps)
    files = _write(tmp_path, [walk, back])
    assert main(["generate", *files, str(tmp_path / "out.bvh"), "--steps", "60", "--start-frame", "10",
                 "--length-to-m", "0.05644"]) == 0
    out, err = capsys.readouterr()
    warn = [ln for ln in err.splitlines() if "warning: the generated motion" in ln]
    assert len(warn) == 1, err
    assert "stands still in 60 of its 60 steps" in warn[0] and "of the capture's pace" in warn[0]
    assert "what helps: --latent-dim 3 or more" in warn[0] and "--rate 30 (every 4th frame of the 120 fps" in warn[0]
    assert "--method knn" in warn[0] and "animsynth resequence" in warn[0]
    assert "wrote " in out and "of the capture's pace)" in out and (tmp_path / "out.bvh").is_file()


def test_a_field_that_moves_is_not_warned_and_rate_fits_at_a_lower_rate(tmp_path, capsys):
    sk = cmu_like_skeleton("p", 2)
    files = _write(tmp_path, [generate_motion("walk_straight", 240, s, sk) for s in range(3)])
    assert main(["generate", *files, str(tmp_path / "out.bvh"), "--steps", "40", "--rate", "30",
                 "--length-to-m", "0.05644"]) == 0
    out, err = capsys.readouterr()
    assert "warning: the generated motion" not in err, err
    assert "41 frames at 30 fps" in out
    assert read_bvh(tmp_path / "out.bvh").fps == pytest.approx(30.0)
    assert main(["generate", *files, str(tmp_path / "out2.bvh"), "--rate", "50", "--length-to-m", "0.05644"]) == 2
    err = capsys.readouterr().err
    assert "argument --rate: 50 fps is not the rate of" in err and "use one of 120, 60, 40, 30, 24" in err
    assert not (tmp_path / "out2.bvh").exists()
