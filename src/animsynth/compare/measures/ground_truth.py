"""Against a ground truth (the LAFAN1 benchmark): the database's position statistics, L2P, L2Q and NPSS."""

from __future__ import annotations

import numpy as np

from .metric_record import Metric
from .pose import HORIZONTAL, align_quaternions, rotate_to

__all__ = ["position_stats", "l2p", "l2q", "npss", "score_l2p", "score_l2p_m", "score_l2q", "score_npss", "RECORDS"]

_NAN = float("nan")


def position_stats(pos_list, forward_list, window: int, stride: int, context: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of every joint coordinate over windows of the database (LAFAN1's L2P stats).

    Windows of ``window`` frames start every ``stride`` frames of each clip. Each window is moved so that the
    mean horizontal centroid of its frames is at the origin and turned about the vertical so that the facing at
    its frame ``context - 1`` (the last context frame) is +z; the statistics run over every frame of every
    window.

    Parameters
    ----------
    pos_list : sequence of ndarray, each shape (T_i, J, 3)
        Metres.
    forward_list : sequence of ndarray, each shape (T_i, 2)
        :func:`facing` of each clip.
    window, stride, context : int
        LAFAN1: 50, 20, 10 at 30 fps.

    Returns
    -------
    mean, std : ndarray, shape (J, 3)
    """
    if not 1 <= context <= window:
        raise ValueError(f"context ({context}) must lie in 1..window ({window})")
    frames = []
    for pos, fwd in zip(pos_list, forward_list):
        pos, fwd = np.asarray(pos, float), np.asarray(fwd, float)
        for s in range(0, pos.shape[0] - window + 1, stride):
            w = pos[s:s + window].copy()
            w[:, :, HORIZONTAL] -= w[:, :, HORIZONTAL].mean(axis=(0, 1))
            frames.append(rotate_to(w, fwd[s + context - 1]))
    if not frames:
        raise ValueError(f"no clip has a window of {window} frames")
    allf = np.concatenate(frames)
    return allf.mean(axis=0), allf.std(axis=0)


def l2p(gen_pos, gt_pos, std, forward=None) -> float:
    """L2P: mean over frames of the L2 norm of the normalised global position error (LAFAN1).

    ``L2P = mean_t sqrt( sum_{j,c} ((gen - gt)_{t,j,c} / std_{j,c})^2 )``; the dataset mean of LAFAN1's
    normalisation cancels in the difference.

    Parameters
    ----------
    gen_pos, gt_pos : ndarray, shape (T, J, 3)
        Metres, world frame.
    std : ndarray, shape (J, 3), or None
        :func:`position_stats`; ``None``: no normalisation (the error in metres).
    forward : ndarray, shape (2,), optional
        The facing the statistics were aligned to (the ground truth's at its last context frame): the errors
        are turned into that frame before the per-coordinate normalisation. ``None``: world axes.

    Returns
    -------
    float
    """
    d = np.asarray(gen_pos, float) - np.asarray(gt_pos, float)
    if d.ndim != 3:
        raise ValueError(f"positions must have shape (T, J, 3), got {d.shape}")
    if forward is not None:
        d = rotate_to(d, np.asarray(forward, float) / np.linalg.norm(forward))
    if std is not None:
        std = np.asarray(std, float)
        if std.shape != d.shape[1:]:
            raise ValueError(f"std has shape {std.shape}, expected {d.shape[1:]}")
        if np.any(std <= 0):
            raise ValueError("std has a zero entry: a joint coordinate never varies in the database windows")
        d = d / std
    return float(np.mean(np.sqrt(np.sum(d ** 2, axis=(1, 2)))))


def l2q(gen_q, gt_q) -> float:
    """L2Q: mean over frames of the L2 norm of the global quaternion error (LAFAN1), sign-aligned.

    Each generated quaternion takes the sign nearer the ground truth's (:func:`align_quaternions`), so one
    joint rotated by ``theta`` from the truth adds ``(2 sin(theta / 4))^2`` under the square root.

    Parameters
    ----------
    gen_q, gt_q : ndarray, shape (T, J, 4)
        Unit global quaternions (:func:`global_quaternions`).

    Returns
    -------
    float
    """
    gt_q = np.asarray(gt_q, float)
    d = align_quaternions(gen_q, gt_q) - gt_q
    return float(np.mean(np.sqrt(np.sum(d ** 2, axis=(1, 2)))))


def npss(gen, gt, spectrum: str = "real", quaternions: bool = False) -> float:
    """NPSS: normalised power spectrum similarity (Gopalakrishnan et al. 2019, as in the LAFAN1 benchmark).

    Per feature dimension ``d`` (trailing axes flattened) the power over the FFT bins along time is
    normalised to sum to 1; the earth mover's distance between the ground truth's and the generated
    cumulative spectra is the L1 norm of their difference (in bins); NPSS is the average of the EMDs weighted
    by the ground truth's total power per dimension. Lower is more similar; 0 for identical signals.

    Parameters
    ----------
    gen, gt : ndarray, shape (T, ...)
        One generated sequence and its ground truth (LAFAN1: global quaternions, (T, J, 4)).
    spectrum : {"real", "power"}
        ``"real"``: the square of the real part of the FFT, what the LAFAN1 benchmark and the authors' code
        compute; ``"power"``: ``|FFT|^2``, the power spectrum of the paper's text (invariant to a circular
        time shift).
    quaternions : bool
        Inputs are quaternions (T, J, 4): ``gt`` is made continuous over time and ``gen`` takes the sign of
        ``gt`` per frame and joint before the spectra (:func:`align_quaternions`).

    Returns
    -------
    float
        Dimensions whose ground truth has zero power carry zero weight and are left out; a generated dimension
        with zero power has a zero cumulative spectrum. NaN when every ground-truth dimension has zero power.
    """
    from scipy.fft import fft

    gen, gt = np.asarray(gen, float), np.asarray(gt, float)
    if gen.shape != gt.shape:
        raise ValueError(f"generated and ground-truth shapes differ: {gen.shape} vs {gt.shape}")
    if quaternions:
        gt = align_quaternions(gt)
        gen = align_quaternions(gen, gt)
    gen, gt = gen.reshape(gen.shape[0], -1), gt.reshape(gt.shape[0], -1)
    if spectrum == "real":
        pg, pt = np.real(fft(gen, axis=0)) ** 2, np.real(fft(gt, axis=0)) ** 2
    elif spectrum == "power":
        pg, pt = np.abs(fft(gen, axis=0)) ** 2, np.abs(fft(gt, axis=0)) ** 2
    else:
        raise ValueError(f"spectrum must be 'real' or 'power', got {spectrum!r}")
    tg, tt = pg.sum(axis=0), pt.sum(axis=0)
    keep = tt > 0
    if not keep.any():
        return _NAN
    cg = np.cumsum(np.divide(pg, tg, out=np.zeros_like(pg), where=tg > 0), axis=0)
    ct = np.cumsum(pt[:, keep] / tt[keep], axis=0)
    emd = np.sum(np.abs(cg[:, keep] - ct), axis=0)
    return float(np.average(emd, weights=tt[keep]))


# ----------------------------------------------------------------------------- the records' computations
# Each takes a :class:`~.scored.ScoredMotion` ``s`` and compares its generated frames with the held-out ground
# truth of the same frames (``s.ref``: ``truth_pos``, ``truth_q``, ``truth_forward``, the run's ``std``).


def score_l2p(s) -> dict:
    """``l2p``: LAFAN1's L2P, normalised by the run's database statistics, errors in the truth's facing."""
    return {"l2p": l2p(s.generated_pos, s.ref.truth_pos, s.ref.std, forward=s.ref.truth_forward)}


def score_l2p_m(s) -> dict:
    """``l2p_m``: L2P in metres (no normalisation)."""
    return {"l2p_m": l2p(s.generated_pos, s.ref.truth_pos, None)}


def score_l2q(s) -> dict:
    """``l2q``: LAFAN1's L2Q on the world rotations."""
    return {"l2q": l2q(s.quaternions, s.ref.truth_q)}


def score_npss(s) -> dict:
    """``npss`` of the world rotations (``compare.metrics.npss_spectrum``)."""
    return {"npss": npss(s.quaternions, s.ref.truth_q, spectrum=s.mcfg["npss_spectrum"], quaternions=True)}


#: this module's columns, in their order in ``metrics.csv``: against a ground truth of the same length, on the
#: short track only
RECORDS = (
    Metric("l2p", "LAFAN1 L2P (clip database statistics)", "lower", "database", "L2P", "L2P vs held-out continuation",
           exploratory=True, margin=0.25,
           margin_why="a quarter of the database's own per-joint position standard deviation (the unit L2P is "
                      "normalised by): a smaller gap to the capture is not a different continuation",
           compute="ground_truth:score_l2p", tracks=("short",)),
    Metric("l2p_m", "m", "lower", "reference", "L2P (m)", compute="ground_truth:score_l2p_m", tracks=("short",)),
    Metric("l2q", "LAFAN1 L2Q", "lower", "reference", compute="ground_truth:score_l2q", tracks=("short",)),
    Metric("npss", "NPSS", "lower", "reference", title="NPSS vs held-out continuation",
           compute="ground_truth:score_npss", tracks=("short",)),
)
