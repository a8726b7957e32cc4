"""Kovar et al.'s motion graph (animsynth.compare.generators.motiongraph): known answers on small synthetic clips."""

from __future__ import annotations

import copy
import functools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from animsynth.compare.generators import fairmotion_load as fl
from animsynth.compare.generators.fairmotion_fixes import FIXES
from animsynth.compare.generators.motiongraph import MotionGraph, kovar_alpha
from animsynth.compare.generators.point_clouds import apply_floor_transform, floor_alignment, pair_terms, window_clouds
from animsynth.generator import check_generated
from animsynth.kinematics import dof_values_from_local, forward_kinematics, local_rotations, root_translation
from animsynth.motion import Motion
from animsynth.synth.mocap import cmu_like_skeleton, generate_motion

FPS = 30.0


def _positions(m: Motion) -> np.ndarray:
    return forward_kinematics(m.skeleton, m.values) * m.skeleton.length_to_m


def _periodic(sk, frames=120, period=30, amp=12.0, seed=0, name="periodic") -> Motion:
    """Joint angles exactly periodic, the root walking straight at constant speed: windows one period
    apart are identical up to a floor translation."""
    base = generate_motion("walk_straight", 20, seed, sk, fps=FPS).values[0]
    cols = sk.columns()
    rot = [i for i, c in enumerate(cols) if not c.startswith("root.") and c.split(".")[1] in ("rx", "ry", "rz")]
    rng = np.random.default_rng(seed)
    t = np.arange(frames)[:, None]
    v = np.tile(base, (frames, 1))
    v[:, rot] += amp * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi, len(rot)))
    v[:, cols.index("root.tz")] = base[cols.index("root.tz")] + 0.7 * t[:, 0]
    return Motion(v, sk, FPS, name)


def _moved(m: Motion, theta: float, x0: float, z0: float, name="moved") -> Motion:
    """The same motion turned by ``theta`` about y and shifted on the floor (skeleton units)."""
    rots = local_rotations(m.skeleton, m.values)
    rots[0] = Rotation.from_euler("y", theta) * rots[0]
    root = apply_floor_transform(root_translation(m.skeleton, m.values)[:, None], theta, x0, z0)[:, 0]
    return Motion(dof_values_from_local(m.skeleton, rots, root), m.skeleton, m.fps, name)


@pytest.fixture(scope="module")
def sk():
    return cmu_like_skeleton("mgtest", 1)


# ---------------------------------------------------------------- the closed form
@pytest.mark.parametrize("theta", [0.7, -2.9, 3.1])
def test_floor_alignment_recovers_a_known_rotation_and_floor_translation(theta):
    rng = np.random.default_rng(3)
    q = rng.normal(size=(40, 3))
    p = apply_floor_transform(q, theta, 1.3, -0.4)
    th, x0, z0, d2 = floor_alignment(p, q, weights=rng.uniform(0.5, 2.0, 40))
    assert np.isclose(th, theta, atol=1e-12) and np.isclose(x0, 1.3, atol=1e-12) and np.isclose(z0, -0.4, atol=1e-12)
    assert d2 < 1e-24
    # a vertical offset is not removed (translation in the floor plane only)
    lifted = p + [0.0, 0.5, 0.0]
    assert np.isclose(floor_alignment(lifted, q)[3], 0.25)


def test_floor_alignment_is_the_minimum_over_rotations():
    rng = np.random.default_rng(5)
    q = rng.normal(size=(30, 3))
    p = apply_floor_transform(q, 1.0, 0.2, 0.1) + rng.normal(scale=0.3, size=q.shape)
    w = rng.uniform(0.1, 1.0, 30)
    th, x0, z0, d2 = floor_alignment(p, q, w)
    wn = w / w.sum()
    grid = np.linspace(-np.pi, np.pi, 20001)
    best = np.inf
    for g in grid[::50]:  # coarse scan, optimal translation for each angle (the weighted centroid difference)
        moved = apply_floor_transform(q, g, 0.0, 0.0)
        shift = wn @ (p - moved)
        shift[1] = 0.0
        best = min(best, float(wn @ ((p - moved - shift) ** 2).sum(1)))
    assert d2 <= best + 1e-12
    assert d2 > best - 1e-3  # and the scan comes close to it


def test_all_pairs_matrix_products_equal_the_closed_form_per_pair():
    rng = np.random.default_rng(7)
    P = rng.normal(size=(6, 25, 3)) + [3.0, 1.0, -2.0]
    Q = rng.normal(size=(4, 25, 3))
    w = rng.uniform(0.2, 1.0, 25)
    w /= w.sum()
    d2, a, b, cp, cq = pair_terms(P, Q, w)
    for i in range(6):
        for j in range(4):
            th, _, _, ref = floor_alignment(P[i], Q[j], w)
            assert np.isclose(d2[i, j], ref, rtol=1e-10, atol=1e-12)
            assert np.isclose(np.arctan2(b[i, j], a[i, j]), th, atol=1e-10)


def test_window_clouds_are_frame_major():
    pos = np.arange(5 * 2 * 3, dtype=float).reshape(5, 2, 3)
    c = window_clouds(pos, 3)
    assert c.shape == (3, 6, 3)
    assert np.array_equal(c[1], pos[1:4].reshape(6, 3))


def test_kovar_alpha_goes_from_source_to_target():
    a = kovar_alpha(10)
    assert a[-1] == 0.0 and 0.95 < a[0] < 1.0 and np.all(np.diff(a) < 0)


# ---------------------------------------------------------------- the graph
def test_two_copies_of_one_clip_give_zero_distance_transitions(sk):
    m = _periodic(sk)
    copy = _moved(m, 0.9, 15.0, -4.0, "copy")
    g = MotionGraph(window=8, threshold=1e-6).fit([m, copy])
    tr = g.transitions_
    cross = tr[tr.from_clip != tr.to_clip]
    # the clip and its copy are joined at the same instant (the window ending at B_j starts at A_i),
    # at zero distance, by the floor transform that undoes the move
    same_instant = cross[cross.to_frame - cross.from_frame == 7]
    assert len(same_instant) > 10 and set(same_instant.from_clip) == {0, 1}
    assert tr.distance.max() < 1e-6
    assert np.allclose(cross[cross.from_clip == 0].theta, -0.9, atol=1e-6)
    assert np.allclose(cross[cross.from_clip == 1].theta, 0.9, atol=1e-6)
    # (and within each clip one period apart: the loops that make the graph strongly connected)
    within = tr[tr.from_clip == tr.to_clip]
    assert len(within) > 0 and np.all((within.to_frame - 7 - within.from_frame) % 30 == 0)


def test_threshold_none_keeps_the_quantile_of_the_candidates(sk):
    m = generate_motion("walk_straight", 150, 4, sk, fps=FPS)
    everything = MotionGraph(window=8, threshold_quantile=1.0).fit([m])
    assert everything.n_below_threshold_ == everything.n_candidates_ > 10
    half = MotionGraph(window=8, threshold_quantile=0.5).fit([m])
    assert half.n_candidates_ == everything.n_candidates_
    assert abs(half.n_below_threshold_ - half.n_candidates_ / 2) <= 1
    assert half.threshold_ < everything.threshold_
    assert MotionGraph(window=8, threshold=0.5).fit([m]).threshold_ == 0.5


def test_scc_pruning_drops_a_dead_end(sk):
    p = _periodic(sk, seed=0, name="loop")
    other = _periodic(sk, amp=25.0, seed=9).values
    q = Motion(np.vstack([p.values[:60], other[60:]]), sk, FPS, "dead_end")  # leaves the loop at frame 60
    g = MotionGraph(window=8, threshold=1e-6).fit([p, q])
    assert g.largest_scc_share_ < 1.0
    assert g.in_graph_[1][:40].any()  # the shared part of the second clip is in the graph ...
    assert not g.in_graph_[1][60:].any()  # ... its other part is a dead end, pruned
    assert not (g.transitions_.to_clip == 1).values[g.transitions_.to_frame.values >= 59].any()
    start = Motion(p.values[:12], sk, FPS, "start")
    for seed in range(5):
        src = g.generate(start, 300, seed).meta["source_frames"]
        assert not np.any((src[:, 0] == 1) & (src[:, 1] >= 60))


def test_transitions_between_moved_copies_are_continuous_and_root_aligned(sk):
    p = _periodic(sk)
    copy = _moved(p, -1.2, -30.0, 12.0, "copy")
    g = MotionGraph(window=8, threshold=1e-6).fit([p, copy])
    start = Motion(p.values[:10], sk, FPS, "start")
    out = g.generate(start, 240, seed=4)
    src = out.meta["source_frames"]
    assert out.meta["seams"].size >= 3 and set(src[src[:, 0] >= 0, 0]) == {0, 1}
    pos = _positions(out)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=-1).max(1)
    db_step = max(np.linalg.norm(np.diff(_positions(c), axis=0), axis=-1).max() for c in (p, copy))
    # the aligned copies are the same motion: across every transition it plays on without a jump,
    # in place and heading (an unaligned cut into the copy would jump by metres)
    assert step.max() <= db_step + 1e-6
    # the first output frame continues the start context
    first_gap = np.linalg.norm(pos[0] - _positions(start)[-1], axis=-1).max()
    assert first_gap <= db_step + 1e-6


def test_blended_transition_between_different_clips_has_no_jump_beyond_the_blend(sk):
    a = generate_motion("walk_straight", 150, 1, sk, fps=FPS)
    b = _moved(generate_motion("walk_straight", 150, 8, sk, fps=FPS), 2.0, 40.0, 10.0, "other_walk")
    g = MotionGraph(window=10).fit([a, b])
    start = Motion(a.values[:10], sk, FPS, "start")
    out = g.generate(start, 300, seed=0)
    seams = out.meta["seams"]
    assert seams.size > 0
    pos = _positions(out)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=-1).max(1)  # step[t-1]: frame t-1 -> t
    db_step = max(np.linalg.norm(np.diff(_positions(c), axis=0), axis=-1).max() for c in (a, b))
    assert step.max() <= 1.5 * db_step
    # without the blend (one-frame transitions) the same graph jumps at its seams
    hard = MotionGraph(window=10, blend=1).fit([a, b]).generate(start, 300, seed=0)
    hard_step = np.linalg.norm(np.diff(_positions(hard), axis=0), axis=-1).max(1)
    assert hard_step[hard.meta["seams"] - 1].max() > step[seams - 1].max()


def test_blended_root_follows_kovar_weights(sk):
    a = generate_motion("walk_straight", 150, 1, sk, fps=FPS)
    b = generate_motion("walk_straight", 150, 8, sk, fps=FPS)
    g = MotionGraph(window=10).fit([a, b])
    out = g.generate(Motion(a.values[:10], sk, FPS, "start"), 200, seed=1)
    s = int(out.meta["seams"][0])
    src = out.meta["source_frames"]
    assert np.all(src[s:s + 10] == -1) and np.all(src[s - 1] >= 0) and np.all(src[s + 10] >= 0)
    # the root height (untouched by the floor alignment) is alpha(p) A + (1 - alpha(p)) B over the blend
    root_y = root_translation(sk, out.values)[:, 1]
    clips = [a, b]
    ca, fa = src[s - 1]
    cb, fb = src[s + 10]
    ya = root_translation(sk, clips[ca].values)[fa + 1:fa + 11, 1]
    yb = root_translation(sk, clips[cb].values)[fb - 10:fb, 1]
    al = kovar_alpha(10)
    assert np.allclose(root_y[s:s + 10], al * ya + (1 - al) * yb, atol=1e-9)


def test_generate_length_and_seeds(sk):
    a = generate_motion("walk_straight", 120, 1, sk, fps=FPS)
    b = generate_motion("run_straight", 90, 2, sk, fps=FPS)
    g = MotionGraph(window=8).fit([a, b])
    start = Motion(a.values[30:40], sk, FPS, "start")
    m1 = g.generate(start, 157, seed=11)
    assert m1.values.shape == (157, sk.n_dof) and m1.fps == FPS and m1.skeleton is a.skeleton
    assert m1.meta["source_frames"].shape == (157, 2)
    assert np.array_equal(m1.values, g.generate(start, 157, seed=11).values)
    assert not np.array_equal(m1.values, g.generate(start, 157, seed=12).values)


def test_search_reaches_the_target_node(sk):
    p = _periodic(sk)
    copy = _moved(p, 0.5, 5.0, 5.0, "copy")
    g = MotionGraph(window=8, threshold=1e-6).fit([p, copy])
    start = Motion(p.values[:10], sk, FPS, "start")
    target_frame = 75
    out = g.search(start, p.values[target_frame], 150)
    t = out.meta["target_frame"]
    assert 0 <= t < out.n_frames == 150  # the path reaches the goal inside the output (-1 if not)
    assert tuple(out.meta["source_frames"][t]) == tuple(out.meta["target_node"])  # frame t plays the goal
    assert out.meta["target_node"][1] % 30 == target_frame % 30  # the same phase of the periodic motion
    assert tuple(out.meta["source_frames"][t]) == out.meta["target_node"]
    # the played frame is the target pose (up to its place on the floor)
    d2 = floor_alignment(_positions(Motion(p.values[[target_frame]], sk, FPS))[0], _positions(out)[t])[3]
    assert d2 < 1e-10


def test_bad_input_is_refused(sk):
    a = generate_motion("walk_straight", 60, 1, sk, fps=FPS)
    with pytest.raises(ValueError, match="fps"):
        MotionGraph(window=8).fit([a, generate_motion("walk_straight", 60, 2, sk, fps=60.0)])
    with pytest.raises(ValueError, match="blend"):
        MotionGraph(window=8, blend=9).fit([a])
    with pytest.raises(RuntimeError, match=r"call fit\(database\) before generate"):  # the interface's error
        MotionGraph().generate(a, 10, 0)
    g = MotionGraph(window=8).fit([a, generate_motion("walk_straight", 60, 3, sk, fps=FPS)])
    with pytest.raises(ValueError, match="fps"):
        g.generate(Motion(a.values[:5], sk, 120.0), 10, 0)


def test_the_motion_graph_is_a_generator_of_the_interface(sk):
    """fit sets ``db_`` (the interface's Database); generate and search refuse what the interface refuses (a start
    of one frame) and their output passes the interface's check; run_notes gives the transitions kept."""
    from animsynth.generator import Database, Generator

    a = generate_motion("walk_straight", 60, 1, sk, fps=FPS)
    g = MotionGraph(window=8).fit([a, generate_motion("walk_straight", 60, 3, sk, fps=FPS)])
    assert isinstance(g, Generator) and isinstance(g.db_, Database) and g.db_.n_frames == 120
    assert g.db_.skeleton is g.skeleton_ and g.db_.fps == g.fps_
    with pytest.raises(ValueError, match="the start needs >= 2 frames"):
        g.generate(Motion(a.values[:1], sk, FPS), 10, 0)
    with pytest.raises(ValueError, match="the start needs >= 2 frames"):
        g.search(Motion(a.values[:1], sk, FPS), a.values[30], 10)
    start = Motion(a.values[:10], sk, FPS, "start")
    for out in (g.generate(start, 25, 0), g.search(start, a.values[30], 25)):
        assert check_generated(out, 25, g.db_.skeleton) is out and out.values.shape == (25, sk.n_dof)
    assert g.run_notes() == {"transitions_kept": float(g.n_below_threshold_)}


# ---------------------------------------------------------------- the fairmotion peer
@functools.cache
def _fairmotion_reason() -> str:
    """Why fairmotion cannot run here ('' when it can): asked once per process (every skip condition below reads
    it at collection; its package-metadata look-up is not free)."""
    from animsynth.compare.generators.fairmotion_peer import FairmotionUnavailable, _fairmotion

    try:
        _fairmotion()
    except FairmotionUnavailable as e:
        return e.reason
    return ""


def test_missing_fairmotion_is_reported_with_the_install_command(sk, monkeypatch):
    import importlib.metadata

    from animsynth.compare.generators.fairmotion_peer import INSTALL_COMMAND, FairmotionGraph, FairmotionUnavailable

    def absent(name):
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(importlib.metadata, "version", absent)
    with pytest.raises(FairmotionUnavailable) as err:
        FairmotionGraph().fit([generate_motion("walk_straight", 60, 1, sk, fps=FPS)])
    assert "not installed" in err.value.reason and INSTALL_COMMAND in err.value.reason
    assert INSTALL_COMMAND == "pip install --no-deps fairmotion==0.0.4 networkx==3.6.1 tqdm==4.70.1"


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_peer_walks_its_graph_on_our_clips(sk):
    from animsynth.compare.generators.fairmotion_peer import FairmotionGraph

    # the clips of _fm below: fairmotion's loading and construction of them are built once in this process (the
    # peer's memos; this graph keeps its own threshold)
    a = generate_motion("walk_straight", 48, 1, sk, fps=FPS)
    b = generate_motion("walk_straight", 48, 8, sk, fps=FPS)
    g = FairmotionGraph(base=8, blend=4, compare=4).fit([a, b])
    assert g.fairmotion_version_ == "0.0.4" and g.n_nodes_ >= 2 and len(g.transitions_) > 0
    start = Motion(a.values[:10], sk, FPS, "start")
    out = g.generate(start, 40, seed=3)
    assert out.values.shape == (40, sk.n_dof) and out.fps == FPS
    assert np.array_equal(out.values, g.generate(start, 40, seed=3).values)  # a walk leaves the graph as it was
    assert not np.array_equal(out.values, g.generate(start, 40, seed=4).values)
    # frames before the first seam are database frames, moved only on the floor; the source bookkeeping says which
    src, seams = out.meta["source_frames"], out.meta["seams"]
    assert seams.size > 0 and np.all((seams > 0) & (seams < 40))
    pos = _positions(out)
    clips = [a, b]
    for t in range(int(seams[0])):
        c, f = src[t]
        assert floor_alignment(pos[t], _positions(clips[c])[f])[3] < 1e-8
    assert np.all(src[seams[0]] == -1)  # a blended frame


# ---------------------------------------------------------------- the peer's fixes and its native rate
_FM_GRAPHS = {}


def _fm(sk, fixes=(), native_fps=None, turn=False):
    """A small fairmotion graph (built once per kind: the fixes change only the walk)."""
    from animsynth.compare.generators.fairmotion_peer import FairmotionGraph

    a = generate_motion("walk_straight", 48, 1, sk, fps=FPS)
    b = generate_motion("walk_straight", 48, 8, sk, fps=FPS)
    if turn:  # the second clip walks another way: a transition into it turns the piece
        b = _moved(b, 1.2, 30.0, -20.0, "b")
    key = (native_fps, turn)
    if key not in _FM_GRAPHS:
        _FM_GRAPHS[key] = FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0,
                                          native_fps=native_fps).fit([a, b])
    g = _FM_GRAPHS[key]
    g.fixes = fixes
    return g, [a, b], Motion(a.values[:10], sk, FPS, "start")


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_output_rate_fix_appends_whole_pieces_at_the_data_rate(sk):
    # released, fed 30 fps: the output is built at 60 fps, so every append cuts the piece short
    g, _, start = _fm(sk)
    g.generate(start, 40, seed=2)
    assert g.last_walk_["out_fps"] == 60.0
    released = np.diff([first for first, _n in g.last_walk_["pieces"]])[1:]
    assert released.size and np.all(released < 8)
    g, _, start = _fm(sk, fixes=("output_rate",))
    g.generate(start, 40, seed=2)
    assert g.last_walk_["out_fps"] == FPS
    # base frames per piece (after the first, which fairmotion cuts at its blend start)
    assert np.all(np.diff([first for first, _n in g.last_walk_["pieces"]])[1:] == 8)


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_blend_source_fix_blends_from_a_moving_source(sk):
    # released: every blend of one append draws the previous piece's last pose, held still
    for fixes, moving in [(("output_rate",), False), (("output_rate", "blend_source"), True)]:
        g, _, start = _fm(sk, fixes=fixes)
        g.generate(start, 40, seed=2)
        src = g.last_walk_["blend_sources"]
        n_blend = 4  # blend frames per append at the data's rate
        assert src.shape[0] >= 2 * n_blend
        steps = np.linalg.norm(np.diff(src.reshape(-1, n_blend, 3), axis=1), axis=-1)  # within one append
        assert (steps.min() > 1e-3) == moving, fixes


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_rigid_turn_fix_turns_the_path_with_the_piece(sk):
    # the first piece appended from the other clip (fresh poses: 0.0.4 moves the poses it appends in place,
    # a defect left as released), past its blend, must be a rigid floor move of its source frames, path and
    # orientation together; released, the orientation turns and the path does not
    base_fixes = ("output_rate", "blend_source")
    worst = {}
    for fixes in (base_fixes, base_fixes + ("rigid_turn",)):
        g, clips, start = _fm(sk, fixes=fixes, turn=True)
        residuals = []
        for seed in range(8):
            out = g.generate(start, 40, seed=seed)
            pos, src = _positions(out), out.meta["source_frames"]
            bounds = list(out.meta["seams"]) + [40]
            first_clip = src[0, 0]
            for lo, hi in zip(bounds[:-1], bounds[1:]):
                t = [i for i in range(lo, hi) if src[i, 0] >= 0]
                if len(t) >= 3 and src[t[0], 0] != first_clip:
                    ref = _positions(clips[src[t[0], 0]])[src[t, 1]]
                    residuals.append(floor_alignment(pos[t].reshape(-1, 3), ref.reshape(-1, 3))[3])
                    break
            if "rigid_turn" not in fixes and residuals and max(residuals) > 1e-4:
                break  # released, one walk whose path does not turn is the defect: more walks cannot undo it
        assert residuals, "no walk turned into the other clip"
        worst[fixes] = max(residuals)
    assert worst[base_fixes + ("rigid_turn",)] < 1e-8
    assert worst[base_fixes] > 1e-4


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_cut_copy_fix_keeps_the_walks_clips_in_place(sk, monkeypatch):
    """Released, ``cut`` hands out the clips' own poses and placing a piece moves them, so the next piece of the
    same clip starts displaced and jumps back after its blend; with ``cut_copy`` no pose of the walk's clips moves
    and no root step of the output is far beyond the database's largest."""
    from animsynth.compare.generators import fairmotion_peer as fp

    seen = []

    class Seen(fl.CopyOnRead):  # the clips one walk reads (its copies of the loaded clips)
        def __init__(self, motions):
            super().__init__(motions)
            seen.append(self)

    monkeypatch.setattr(fp, "CopyOnRead", Seen)

    def poses(m):
        return np.array([np.asarray(p.data) for p in m.poses])

    worst, moved = {}, {}
    for fixes in ((), FIXES[:3], FIXES):
        g, clips, start = _fm(sk, fixes=fixes, native_fps=60.0, turn=True)
        db_step = max(np.linalg.norm(np.diff(_positions(c)[:, 0], axis=0), axis=-1).max() for c in clips)
        ratios, n_moved = [], 0
        for seed in range(8):
            seen.clear()
            out = g.generate(start, 40, seed=seed)
            ratios.append(np.linalg.norm(np.diff(_positions(out)[:, 0], axis=0), axis=-1).max() / db_step)
            view = seen[-1]
            assert view._copies
            n_moved += sum(not np.array_equal(poses(m), poses(g._loaded_[i])) for i, m in view._copies.items())
            if fixes != FIXES and n_moved > 0 and max(ratios) > 5.0:
                break  # the rows without cut_copy need one walk that shows the defect: more walks cannot undo it
        worst[fixes], moved[fixes] = max(ratios), n_moved
    assert moved[FIXES] == 0 and worst[FIXES] < 1.5
    assert moved[FIXES[:3]] > 0 and worst[FIXES[:3]] > 5.0  # the other three fixes alone
    assert moved[()] > 0 and worst[()] > 5.0  # the released row: as released


def test_fairmotion_runs_at_its_native_rate_and_answers_at_ours(sk):
    g, clips, start = _fm(sk, native_fps=60.0)
    g.fixes = ()
    assert g.native_fps_ == 60.0 and g.upsample_ == 2 and g._graph_.fps == 60.0
    out = g.generate(start, 40, seed=1)
    assert out.fps == FPS and out.values.shape == (40, sk.n_dof)
    # before the first seam the output plays database frames (every second frame of the 60 fps walk)
    src, seams = out.meta["source_frames"], out.meta["seams"]
    pos = _positions(out)
    for t in range(int(seams[0])):
        c, f = src[t]
        assert floor_alignment(pos[t], _positions(clips[c])[f])[3] < 1e-8


def test_upsample_keeps_every_frame_and_interpolates_between():
    from animsynth.compare.generators.fairmotion_load import upsample

    sk = cmu_like_skeleton("up", 2)
    m = generate_motion("walk_straight", 20, 3, sk, fps=FPS)
    u = upsample(m, 2)
    assert u.fps == 2 * FPS and u.n_frames == 39
    assert np.allclose(_positions(u)[::2], _positions(m), atol=1e-9)
    mid = _positions(u)[1::2]
    assert np.all(np.linalg.norm(mid - 0.5 * (_positions(m)[:-1] + _positions(m)[1:]), axis=-1) < 0.02)


def test_budget_gives_every_graph_generator_the_same_transition_count(sk):
    from animsynth.compare.generators.motiongraph import budget_count

    a = generate_motion("walk_straight", 48, 1, sk, fps=FPS)
    b = generate_motion("walk_straight", 48, 8, sk, fps=FPS)
    seconds = (a.n_frames + b.n_frames) / FPS
    counts = {}
    for budget in (1.0, 2.0):
        ours = MotionGraph(window=6, transitions_per_s=budget).fit([a, b])
        counts[("ours", budget)] = ours.n_below_threshold_
        if not _fairmotion_reason():
            from animsynth.compare.generators.fairmotion_peer import FairmotionGraph

            fm = FairmotionGraph(base=8, blend=4, compare=4, transitions_per_s=budget, fixes=FIXES,
                                 native_fps=60.0).fit([a, b])  # both rows build this graph (fixes: the walk)
            counts[("fairmotion", budget)] = fm.n_below_threshold_
        assert {v for (_g, bb), v in counts.items() if bb == budget} == {budget_count(budget, seconds)}
    assert counts[("ours", 1.0)] == 3 and counts[("ours", 2.0)] == 6
    # a budget beyond a graph's candidates keeps all of them (documented: the peer's 0.5 s nodes give few pairs
    # on short databases, so at 8 per second the r1/r2 clips keep fewer than the budget)
    huge = MotionGraph(window=6, transitions_per_s=1000.0).fit([a, b])
    assert huge.n_below_threshold_ < budget_count(1000.0, seconds) and huge.n_below_threshold_ == huge.n_candidates_
    if _fairmotion_reason():
        pytest.skip(f"the peer's half of this test needs fairmotion: {_fairmotion_reason()}")


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_loads_a_shared_trial_once_and_builds_what_a_fresh_load_builds(sk):
    """Two leave-one-out databases share a trial: the second build reuses fairmotion's loading of it (after
    walks on the first graph, which move poses in place) and equals a build from a cold start."""
    from animsynth.compare.generators import fairmotion_peer as fp

    # 24 frames (47 at fairmotion's 60 fps): two 16-frame nodes per clip, enough for transitions between the
    # clips and walks through them; the loading memo's work is the same at any length, its cost is not
    a, b, c = (generate_motion("walk_straight", 24, s, sk, fps=FPS) for s in (1, 8, 5))
    start = Motion(c.values[:10], sk, FPS, "start")

    def build(db):
        g = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0,
                               fixes=FIXES).fit(db)
        return g, g.transitions_.to_numpy(), [g.generate(start, 30, seed=s).values for s in (1, 2)]

    fl.LOADED.clear()
    _, cold_tr, cold_walks = build([c, b])
    assert len(fl.LOADED) == 2 and len(cold_tr) > 0  # transitions to walk through, at this size too
    fl.LOADED.clear()
    g1, _, _ = build([a, b])  # b loaded here, then its poses walked over
    g1.generate(Motion(a.values[:10], sk, FPS, "s"), 30, seed=7)
    _, warm_tr, warm_walks = build([c, b])
    assert len(fl.LOADED) == 3  # a, b, c: b was loaded once
    assert np.array_equal(cold_tr, warm_tr)
    assert all(np.array_equal(x, y) for x, y in zip(cold_walks, warm_walks))


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_reuses_its_construction_across_rows_and_budgets(sk):
    """The as-released row, the fixed row and another budget on one database: the second and third fits reuse
    the first's construction and give what a cold build gives (transitions, threshold, walks)."""
    from animsynth.compare.generators import fairmotion_peer as fp

    a, b = (generate_motion("walk_straight", 48, s, sk, fps=FPS) for s in (1, 8))
    start = Motion(a.values[:10], sk, FPS, "start")

    def build(budget, fixes):
        g = fp.FairmotionGraph(base=8, blend=4, compare=4, transitions_per_s=budget, native_fps=60.0,
                               fixes=fixes).fit([a, b])
        return g, g.transitions_.to_numpy(), [g.generate(start, 30, seed=s).values for s in (1, 2)]

    cold = {}
    for budget, fixes in ((2.0, ()), (2.0, FIXES), (4.0, FIXES)):
        fl.CONSTRUCTED.clear()
        fl.LOADED.clear()
        g, tr, walks = build(budget, fixes)
        assert not g.construct_reused_
        cold[budget, fixes] = (g.threshold_, g.n_nodes_, tr, walks)
    fl.CONSTRUCTED.clear()
    reused = []
    for budget, fixes in ((2.0, ()), (2.0, FIXES), (4.0, FIXES)):
        g, tr, walks = build(budget, fixes)
        reused.append(g.construct_reused_)
        t, n, tr0, w0 = cold[budget, fixes]
        assert (g.threshold_, g.n_nodes_) == (t, n)
        assert np.array_equal(tr, tr0)
        assert all(np.array_equal(x, y) for x, y in zip(walks, w0))
    assert reused == [False, True, True]
    assert len(fl.CONSTRUCTED) == 1
    # another comparison count is another graph
    fp.FairmotionGraph(base=8, blend=4, compare=4, transitions_per_s=2.0, native_fps=60.0, num_comparison=2).fit([a, b])
    assert len(fl.CONSTRUCTED) == 2


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_construct_in_process_equals_its_pool(sk):
    """``construct``'s node comparisons mapped in this process (default) give the graph fairmotion's own
    one-worker pool gives (``pool=True``, as released): the same nodes and every edge's weight to the bit,
    in the same order; and the walks on both are equal."""
    from animsynth.compare.generators import fairmotion_peer as fp

    # 24 frames (47 at 60 fps): six nodes and 36 edges, every pair of nodes compared in both mappings, as on
    # longer clips (construct's cost grows with the square of the nodes, its comparisons do not change kind)
    a, b, c = (generate_motion(kind, 24, s, sk, fps=FPS) for kind, s in
               (("walk_straight", 1), ("walk_turn", 8), ("walk_straight", 5)))
    start = Motion(a.values[:10], sk, FPS, "start")
    graphs = {}
    for pool in (True, False):
        fl.CONSTRUCTED.clear()
        fl.LOADED.clear()
        g = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0,
                               fixes=FIXES, pool=pool).fit([a, b, c])
        assert not g.construct_reused_
        key = next(iter(fl.CONSTRUCTED))
        graphs[pool] = (fl.CONSTRUCTED[key], g.transitions_.to_numpy(),
                        [g.generate(start, 30, seed=s).values for s in (1, 2)])
    (nodes_p, edges_p), tr_p, walks_p = graphs[True]
    (nodes_s, edges_s), tr_s, walks_s = graphs[False]
    assert len(edges_p) > len(nodes_p) > 3
    assert nodes_s == nodes_p
    assert [(u, v) for u, v, _ in edges_s] == [(u, v) for u, v, _ in edges_p]
    assert np.array_equal(np.array([w for *_, w in edges_s]), np.array([w for *_, w in edges_p]))
    assert np.array_equal(tr_s, tr_p)
    assert all(np.array_equal(x, y) for x, y in zip(walks_s, walks_p))


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_walks_copy_only_the_clips_they_read(sk, monkeypatch):
    """Each walk copies a clip the first time it reads it (``CopyOnRead``, one memo: the clips' shared skeleton
    copied once) and walks exactly as on a deep copy of every clip; the loaded clips stay untouched."""
    from animsynth.compare.generators import fairmotion_peer as fp

    # 24 frames (47 at 60 fps): eight nodes on four clips; the walks of seeds 1 and 2 read three and two of the
    # four clips (what the lazy copy is about) and the size of a clip does not change what its copy is
    clips = [generate_motion(kind, 24, s, sk, fps=FPS) for kind, s in
             (("walk_straight", 1), ("walk_turn", 8), ("walk_straight", 5), ("walk_turn", 3))]
    start = Motion(clips[0].values[:10], sk, FPS, "start")
    g = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0,
                           fixes=FIXES).fit(clips)
    before = [np.array([np.asarray(p.data) for p in m.poses]) for m in g._loaded_]
    views = []

    class Seen(fl.CopyOnRead):  # the lazy copy, each walk's view kept to count the clips it copied
        def __init__(self, motions):
            super().__init__(motions)
            views.append(self)

    monkeypatch.setattr(fp, "CopyOnRead", Seen)
    lazy = [g.generate(start, 40, seed=s).values for s in (1, 2, 3)]
    monkeypatch.undo()
    assert len(views) == 3 and min(len(v._copies) for v in views) < len(clips)  # some walk left a clip uncopied
    assert all(np.array_equal(x, np.array([np.asarray(p.data) for p in m.poses]))
               for x, m in zip(before, g._loaded_))
    seen = []

    class Whole(fl.CopyOnRead):  # the copy before: every clip deep-copied at once
        def __init__(self, motions):
            super().__init__(motions)
            whole = copy.deepcopy(self._src)
            self._copies = dict(enumerate(whole))
            seen.append(self)

    monkeypatch.setattr(fp, "CopyOnRead", Whole)
    whole = [g.generate(start, 40, seed=s).values for s in (1, 2, 3)]
    assert len(seen) == 3
    assert all(np.array_equal(x, y) for x, y in zip(lazy, whole))
    monkeypatch.undo()
    # a walk reads some clips: those are copied, with one skeleton between them
    view = fl.CopyOnRead(g._loaded_)
    m0, m2 = view[0], view[np.int64(2)]
    assert view[0] is m0 and m0 is not g._loaded_[0]
    assert m0.skel is m2.skel and m0.skel is not g._loaded_[0].skel
    assert sorted(view._copies) == [0, 2]
    assert view[-1] is view[3]
    with pytest.raises(IndexError):
        view[4]


# ---------------------------------------------------------------- the native-rate clips (fed from the source)
def _trials_120(sk, frames=240):
    from animsynth.synth.mocap import generate_motion as gm

    return {f"t{i}": gm(kind, frames, s, sk, name=f"t{i}")  # 120 fps, 2 s each by default
            for i, (kind, s) in enumerate((("walk_straight", 1), ("walk_turn", 8), ("walk_straight", 5)))}


_CC = {"fps": 30, "context": 8, "length": 20, "min_length": 6, "split_blocks": 3}


def test_clips_carry_the_native_rate_database_and_start_from_the_source(sk, tmp_path):
    from animsynth.compare import protocol
    from animsynth.retarget import unwrap_angles

    trials = _trials_120(sk)
    clips = protocol.prepare_clips(trials, {"w": ["t0", "t1", "t2"]}, {"split": "t1"}, dict(_CC, native_fps=[60.0]))
    trials = {t: unwrap_angles(m) for t, m in trials.items()}  # the clips hold the unwrapped trials
    for c in clips:
        assert len(c.native) == 1
        nat = c.at_rate(60.0)
        assert nat.fps == 60.0 and nat.note == "" and c.at_rate(90.0) is None
        src = trials[c.trial].values[::2]  # 120 -> 60 fps: every second source frame
        assert nat.start.n_frames == (c.context - 1) * 2 + 1
        assert np.array_equal(nat.start.values[::2], c.start.values)  # the same instants as the working start
        assert np.array_equal(nat.start.values, src[2 * c.frame:2 * c.frame + nat.start.n_frames])
        for d, n, name in zip(c.database, nat.database, c.database_names):
            assert np.array_equal(n.values[::2], d.values) and n.fps == 60.0 and n.name == d.name
            if c.protocol == "leave one out":  # whole trials
                assert np.array_equal(n.values, trials[name].values[::2])
            else:  # the trial's frames before or after the block: nothing of the held-out part
                a, b = (int(x) for x in d.name.split("[")[1].rstrip("]").split(":"))
                assert np.array_equal(n.values, src[2 * a:2 * b]) and not a <= c.frame < b
    assert {c.protocol for c in clips} == {"leave one out", "temporal split"}
    # stored and read back
    protocol.save_clips(tmp_path / "c.npz", clips)
    back = protocol.load_clips(tmp_path / "c.npz")
    for a, b in zip(clips, back):
        x, y = a.at_rate(60.0), b.at_rate(60.0)
        assert np.array_equal(x.start.values, y.start.values) and y.start.fps == 60.0
        assert all(np.array_equal(p.values, q.values) and p.name == q.name for p, q in zip(x.database, y.database))
    table = protocol.clips_table(back)
    assert list(table["native_fps"]) == ["60"] * len(back) and list(table["note"]) == [""] * len(back)
    old = protocol.prepare_clips(trials, {"w": ["t0", "t1", "t2"]}, {}, _CC)
    assert all(c.native == [] for c in old)


def test_a_source_rate_that_is_no_multiple_of_the_native_rate_falls_back_with_a_note(sk, caplog):
    from animsynth.compare import protocol

    trials = {k: Motion(v.values, v.skeleton, 90.0, k) for k, v in _trials_120(sk).items()}  # 90 fps: 60 does not divide it
    with caplog.at_level("INFO", logger="animsynth.compare.protocol"):
        clips = protocol.prepare_clips(trials, {"w": ["t0", "t1", "t2"]}, {}, dict(_CC, native_fps=[60.0]))
    nat = clips[0].at_rate(60.0)
    assert nat.database == [] and nat.start is None and "not a whole multiple of 60" in nat.note
    assert "upsample" in nat.note and "no 60 fps database" in caplog.text
    assert all("not a whole multiple" in n for n in protocol.clips_table(clips)["note"])


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_fairmotion_builds_on_the_sources_60_fps_frames_not_the_30_fps_clips_upsampled(sk, monkeypatch):
    """Given the clips' 60 fps database (the runner passes it), fairmotion's loaded frames are the source trial's
    every second frame, not an interpolation of the 30 fps clip; without it, the upsampled clip as before."""
    from animsynth.compare.generators import fairmotion_peer as fp
    from animsynth.compare import protocol, runner

    # 1.5 s trials: a database of two 45-frame clips, five fairmotion nodes each (its three fits, loading and
    # construction grow with the clips; what the test compares, the loaded frames, does not depend on the length)
    trials = _trials_120(sk, 180)
    clips = protocol.prepare_clips(trials, {"w": ["t0", "t1", "t2"]}, {}, dict(_CC, native_fps=[60.0]))
    clip = clips[0]

    def root_m(loaded):  # fairmotion's root positions (metres, the BVH is written in metres)
        return np.array([np.asarray(p.data)[0, :3, 3] for p in loaded.poses])

    gen = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0, fixes=FIXES)
    fit_kw, gen_kw = runner.native_inputs(gen, clip)
    assert set(fit_kw) == {"native_clips"} and set(gen_kw) == {"native_start"}
    gen.fit(clip.database, **fit_kw)
    assert gen.native_input_ == "source" and gen.upsample_ == 2
    old = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0).fit(clip.database)
    assert old.native_input_ == "upsampled"
    for i, name in enumerate(clip.database_names):
        source = positions_m_root(trials[name].values[::2], sk)
        got, up = root_m(gen._loaded_[i]), root_m(old._loaded_[i])
        assert got.shape == source.shape and np.allclose(got, source, atol=1e-6)
        n = min(len(up), len(source))
        assert np.abs(up[1:n:2] - source[1:n:2]).max() > 1e-4  # the upsampled clip interpolates between
        assert np.allclose(up[0:n:2], source[0:n:2], atol=1e-6)  # and agrees on the working frames
    out = gen.generate(clip.start, clip.length, 3, **gen_kw)
    assert out.fps == 30.0 and out.values.shape == (clip.length, sk.n_dof)
    # the runner passes them
    seen = []
    real = fp.FairmotionGraph.fit

    def spy(self, database, native_clips=None):
        seen.append(native_clips)
        return real(self, database, native_clips=native_clips)

    monkeypatch.setattr(fp.FairmotionGraph, "fit", spy)
    from conftest import default_config
    from animsynth.compare import settings

    config = default_config()
    cfg = dict(settings.job_cfg(config, "fairmotion_fixed"), seeds=1)
    cfg["fairmotion"] = dict(cfg["fairmotion"], base=8, blend=4, compare=4)
    runner.run_generator(clips[:1], "fairmotion_fixed", cfg, 7)
    assert seen and seen[0] is clip.at_rate(60.0).database


@pytest.mark.skipif(bool(_fairmotion_reason()), reason=_fairmotion_reason() or "fairmotion installed")
def test_the_fairmotion_peer_is_a_generator_of_the_interface_on_what_it_is_given(sk):
    """fit sets ``db_`` (the working clips) and ``native_db_`` (the 60 fps clips fairmotion is given); generate
    refuses an unfitted peer and a start of one frame, at the working and at the native rate, with the interface's
    errors; its output passes the interface's check; run_notes gives the node pairs kept."""
    from animsynth.compare.generators import fairmotion_peer as fp
    from animsynth.compare import protocol, runner
    from animsynth.generator import Database, Generator

    # the trials of the test above: its fits' loading and construction are built once in this process
    clip = protocol.prepare_clips(_trials_120(sk, 180), {"w": ["t0", "t1", "t2"]}, {}, dict(_CC, native_fps=[60.0]))[0]
    gen = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0, fixes=FIXES)
    assert isinstance(gen, Generator)
    with pytest.raises(RuntimeError, match=r"call fit\(database\) before generate"):
        gen.generate(clip.start, clip.length, 0)
    fit_kw, gen_kw = runner.native_inputs(gen, clip)
    gen.fit(clip.database, **fit_kw)
    assert isinstance(gen.db_, Database) and isinstance(gen.native_db_, Database)
    assert (gen.db_.fps, gen.native_db_.fps) == (30.0, 60.0) and gen.native_db_.clips == list(fit_kw["native_clips"])
    one = clip.start.values[-1:]
    with pytest.raises(ValueError, match="the start needs >= 2 frames"):
        gen.generate(Motion(one, sk, 30.0, "one"), clip.length, 0, **gen_kw)
    native_one = Motion(gen_kw["native_start"].values[-1:], sk, 60.0, "one")
    with pytest.raises(ValueError, match="the start needs >= 2 frames"):
        gen.generate(clip.start, clip.length, 0, native_start=native_one)
    out = gen.generate(clip.start, clip.length, 3, **gen_kw)
    assert check_generated(out, clip.length, gen.db_.skeleton) is out
    assert gen.run_notes() == {"transitions_kept": float(gen.n_below_threshold_)}
    upsampled = fp.FairmotionGraph(base=8, blend=4, compare=4, threshold_quantile=1.0, native_fps=60.0).fit(
        clip.database)
    assert upsampled.native_db_ is None and upsampled.db_.fps == 30.0


def positions_m_root(values, sk):
    return root_translation(sk, values) * sk.length_to_m


def test_native_rate_clips_match_the_working_clips_through_wraps_branches_and_other_bone_lengths(sk):
    """The native-rate clip is made like the working-rate one: a trial whose angles wrap (unwrapped), one on
    another angle branch (shifted to the first database trial's) and one with other bone lengths (retargeted
    onto the held-out trial's skeleton): every second 60 fps frame is the 30 fps clip's, start and database."""
    import copy

    from animsynth.compare import protocol

    trials = _trials_120(sk)
    col = trials["t1"].skeleton.columns().index("lfemur.rx")
    v = trials["t1"].values.copy()
    v[:, col] = (v[:, col] + 170.0 + 180.0) % 360.0 - 180.0  # sits near +-180: wraps as the leg swings
    trials["t1"] = Motion(v, trials["t1"].skeleton, trials["t1"].fps, "t1")
    v0 = trials["t0"].values.copy()
    v0[:, col] += 360.0  # the same rotations on another branch
    trials["t0"] = Motion(v0, trials["t0"].skeleton, trials["t0"].fps, "t0")
    longer = copy.deepcopy(trials["t2"].skeleton)
    for j in longer.joints[1:]:
        j.offset = np.asarray(j.offset, float) * 1.1
    trials["t2"] = Motion(trials["t2"].values, longer, trials["t2"].fps, "t2")
    assert np.any(np.abs(np.diff(trials["t1"].values[:, col])) > 180)
    clips = protocol.prepare_clips(trials, {"w": ["t0", "t1", "t2"]}, {"split": "t1"}, dict(_CC, native_fps=[60.0]))
    for c in clips:
        nat = c.at_rate(60.0)
        assert np.array_equal(nat.start.values[::2], c.start.values), c.clip
        for d, n in zip(c.database, nat.database):
            assert np.array_equal(n.values[::2][:d.n_frames], d.values), c.clip
            assert n.skeleton is c.held_out.skeleton or n.skeleton.columns() == c.held_out.skeleton.columns()
        assert np.abs(np.diff(nat.start.values[:, col])).max() < 180 and np.abs(np.diff(c.start.values[:, col])).max() < 180
