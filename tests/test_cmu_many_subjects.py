"""Real data: every trial of config/cmu.yaml read as the parse job reads it, the six subjects added on their own
skeletons checked against the mirror's trials.csv, the capture check's flags and the generic figure of 06 and 10.

Skipped with the reason when ../shared/data (or ANIMSYNTH_SHARED_DATA) is absent."""

import csv

import numpy as np
import pytest

from animsynth.axes import standing_height
from animsynth.capture_check import check_capture
from animsynth.joints import ROLES, resolve_roles
from animsynth.kinematics import forward_kinematics
from animsynth.skeleton import figure_kinds, shared_figures
from cmu_yaml_trials import cmu_yaml_trials, paper_config, read_trial
from conftest import CMU, CMU_MANY, need

pytestmark = pytest.mark.realdata

NEW_SUBJECTS = ("26", "27", "32", "36", "91", "131")
#: what the capture check flags in config/cmu.yaml's trials with the schema's thresholds: (kind, first, last)
#: frames of the parsed trial at 120 fps (docs/data.md, "Capture checks"); every other trial is clean
EXPECTED_FLAGS = {
    "35_13": [("jump", 35, 36)],
    "35_22": [("frozen", 156, 166)],
    "35_19": [("jump", 103, 104), ("jump", 109, 110)],
    "49_04": [("frozen", 245, 250)],
    "06_01": [("tpose_settling", 0, 3)],
    "10_04": [("tpose_settling", 0, 3)],
}


@pytest.fixture(scope="module")
def trials():
    """{trial id: (record, Motion, [warnings logged while loading it])} of every trial of config/cmu.yaml, read as
    the parse job reads them (tests/cmu_yaml_trials.py: parsed once per process, this module's own copy)."""
    need(CMU / "subjects")
    need(CMU_MANY / "subjects")
    return cmu_yaml_trials()


@pytest.fixture(scope="module")
def paper():
    """The paper run's config (config/config.yaml with config/cmu.yaml over it, validated)."""
    return paper_config()


def test_the_six_subjects_parse_as_their_files_say(trials):
    """Every trial of 26, 27, 32, 36, 91, 131: the frame count and rate of trials.csv (a BVH's T-pose frame 0
    dropped by first_frame), a figure 1.25 to 1.95 m from its lowest point to the end of its head segment (median
    over frames: CMU's head segment ends about 10-15 cm below the top of the head), the lowest point on the median
    frame within 5 cm below to 10 cm above y = 0 (the feet on the capture's floor), every joint role resolved,
    and no warning while loading."""
    with open(CMU_MANY / "trials.csv", newline="") as fh:
        listed = {r["trial"]: r for r in csv.DictReader(fh) if r["trial"]}
    new = [tid for tid, (t, _, _) in trials.items() if t["subject"] in NEW_SUBJECTS]
    assert sorted({trials[tid][0]["subject"] for tid in new}) == sorted(NEW_SUBJECTS) and len(new) == 13
    for tid in new:
        t, m, warnings = trials[tid]
        assert warnings == [], tid
        row = listed[t["id"]]
        assert (m.n_frames, m.fps) == (int(row["frames"]) - t.get("first_frame", 0), float(row["fps"])), tid
        height = standing_height(m.skeleton, m.values, "+y") * m.skeleton.length_to_m
        assert 1.25 < height < 1.95, (tid, height)
        low = forward_kinematics(m.skeleton, m.values, ends=True)[:, :, 1].min(axis=1) * m.skeleton.length_to_m
        assert -0.05 < float(np.median(low)) < 0.10, (tid, float(np.median(low)))
        assert len(resolve_roles(m.skeleton, list(ROLES))) == len(ROLES)


def test_the_capture_check_flags_these_frames_and_no_others(trials, paper):
    cfg = paper["capture_check"]
    found = {}
    for tid, (t, m, _) in trials.items():
        c = check_capture(m, tid, cfg, first_frame=t.get("first_frame", 0))
        if c.flags:
            found[tid] = [(f.kind, f.first, f.last) for f in c.flags]
        assert c.usable.sum() == m.n_frames - sum(f.n_frames for f in c.flags)
    assert found == EXPECTED_FLAGS


def test_the_motionbuilder_files_frame_0_is_a_t_pose(trials, paper):
    """Read with frame 0 (first_frame 0), 26_01, 27_01, 32_01 and 32_02 start in a T-pose that jumps into the
    capture: frames 0 and 1 flagged; with the record's first_frame 1 nothing is."""
    cfg = paper["capture_check"]
    for tid in ("26_01", "27_01", "32_01", "32_02"):
        c = check_capture(read_trial(paper, trials[tid][0], first_frame=0), tid, cfg)
        assert [(f.kind, f.first, f.last) for f in c.flags] == [("tpose_settling", 0, 1)], tid


def test_only_06_and_10_share_a_figure(trials):
    skeletons = {tid: m.skeleton for tid, (_, m, _) in trials.items()}
    subjects = {tid: t["subject"] for tid, (t, _, _) in trials.items()}
    kinds = figure_kinds(shared_figures(skeletons, subjects))
    assert {s for s, k in kinds.items() if k == "generic"} == {"06", "10"}
    assert sum(k == "own" for k in kinds.values()) == 16
