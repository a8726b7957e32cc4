"""The synthetic mocap must look like locomotion (and be deterministic)."""

import numpy as np
import pytest

from animsynth.kinematics import forward_kinematics
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

FPS = 120.0


def _feet(kind, seed=4, frames=480):
    sk = cmu_like_skeleton("syn35", 7)
    m = generate_motion(kind, frames, seed, sk)
    p = forward_kinematics(sk, m.values) * sk.length_to_m
    low = lambda a, b: np.minimum(p[:, sk.index(a), 1], p[:, sk.index(b), 1])  # noqa: E731
    return sk, m, p, low("lfoot", "ltoes"), low("rfoot", "rtoes")


def test_deterministic_and_seed_dependent():
    sk = cmu_like_skeleton("a", 1)
    a = generate_motion("walk_turn", 100, 3, sk).values
    b = generate_motion("walk_turn", 100, 3, sk).values
    c = generate_motion("walk_turn", 100, 4, sk).values
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    assert not np.allclose(cmu_like_skeleton("a", 1).joints[5].tail, cmu_like_skeleton("b", 1).joints[5].tail)


@pytest.mark.parametrize("kind", ["walk_straight", "walk_turn", "run_straight", "run_turn", "dance"])
def test_plausible_joint_ranges_and_body(kind):
    sk, m, p, lf, rf = _feet(kind)
    assert m.values.shape == (480, 62) and np.all(np.isfinite(m.values))
    cols = sk.columns()
    for j in sk.joints[1:]:
        for k, d in enumerate(j.dofs):
            lo, hi = j.limits[k]
            v = m.values[:, cols.index(f"{j.name}.{d}")]
            assert v.min() >= lo - 25 and v.max() <= hi + 25, (j.name, d, v.min(), v.max())
    knee = m.values[:, cols.index("ltibia.rx")]
    assert knee.min() >= 0 and knee.max() < 150
    head = p[:, sk.index("head"), 1]
    assert 1.3 < head.min() and head.max() < 2.0  # upright adult, metres
    assert min(lf.min(), rf.min()) > -0.005  # never through the floor
    assert min(lf.min(), rf.min()) < 0.005  # but on it


def _runs(mask):
    """Number of separate runs of True."""
    m = np.asarray(mask, int)
    return int(np.sum(np.diff(np.r_[0, m]) == 1))


def test_walking_alternates_foot_contacts_without_flight():
    sk, m, p, lf, rf = _feet("walk_straight")
    c = 0.02
    assert np.mean((lf > c) & (rf > c)) == 0.0  # walking: never both feet in the air
    left_only, right_only = (lf < c) & (rf >= c), (rf < c) & (lf >= c)
    seq = []
    for l_, r_ in zip(left_only, right_only):
        s = "L" if l_ else "R" if r_ else None
        if s and (not seq or seq[-1] != s):
            seq.append(s)
    # 4 s at ~0.9 cycles/s: at least 6 single-support phases, strictly alternating
    assert len(seq) >= 6 and all(a != b for a, b in zip(seq, seq[1:]))
    speed = np.linalg.norm(p[-1, 0, [0, 2]] - p[0, 0, [0, 2]]) / (480 / FPS)
    assert 0.8 < speed < 1.8  # m/s


def test_running_has_flight_phases():
    sk, m, p, lf, rf = _feet("run_straight")
    flight = (lf > 0.02) & (rf > 0.02)
    cycles = 480 / FPS * 1.35
    assert _runs(flight) >= int(2 * cycles) - 1  # two flights per gait cycle
    assert 0.08 < flight.mean() < 0.45
    speed = np.linalg.norm(p[-1, 0, [0, 2]] - p[0, 0, [0, 2]]) / (480 / FPS)
    assert 1.8 < speed < 4.5


def test_turning_changes_heading_and_straight_does_not():
    def heading_change(kind):
        sk, m, p, _, _ = _feet(kind, seed=11)
        d = p[:, 0, [0, 2]]
        v0, v1 = d[120] - d[0], d[-1] - d[-121]
        ang = np.degrees(np.arctan2(v0[0] * v1[1] - v0[1] * v1[0], v0 @ v1))
        return abs(ang)
    assert heading_change("walk_turn") > 30
    assert heading_change("walk_straight") < 20


def test_bad_arguments():
    with pytest.raises(ValueError, match="unknown motion kind"):
        generate_motion("crawl", 100, 1)
    with pytest.raises(ValueError, match="frames must be"):
        generate_motion("walk_straight", 3, 1)
