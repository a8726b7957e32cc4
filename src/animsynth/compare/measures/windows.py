"""Against the database: nearest windows (coverage, local diversity), novelty and the diversity across seeds.

Frame distance: these compare :func:`~animsynth.compare.measures.pose.pose_features` rows, scaled so that the Euclidean
distance of two rows is the root-mean-square distance of corresponding joints (metres) in the body frame."""

from __future__ import annotations

import numpy as np

from .metric_record import Metric

__all__ = ["window_nearest", "window_scores", "coverage", "local_diversity", "seed_diversity", "novelty", "score_windows",
           "score_novelty", "run_seed_diversity", "COVERAGE", "RECORDS"]

_NAN = float("nan")


def _seq_list(x) -> list[np.ndarray]:
    if isinstance(x, np.ndarray) and x.ndim == 2:
        return [np.asarray(x, float)]
    out = [np.asarray(a, float) for a in x]
    for a in out:
        if a.ndim != 2:
            raise ValueError(f"feature sequences must have shape (T, F), got {a.shape}")
    return out


def window_nearest(a, b, length: int, block: int = 4096) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Nearest-window distances between two sets of feature sequences, both ways.

    The distance of window ``[i, i + length)`` of a sequence of ``a`` to window ``[k, k + length)`` of a
    sequence of ``b`` is the mean over its ``length`` frames of the frame distance (Euclidean distance of
    feature rows; m for :func:`pose_features`). Windows never cross the end of a sequence.

    Parameters
    ----------
    a, b : ndarray (T, F) or sequence of them
    length : int
        Window length (frames).
    block : int
        Frames of a ``b`` sequence compared at once (memory: ``len(a_i) * block`` floats).

    Returns
    -------
    a_min : list of ndarray, one per ``a`` sequence, shape (T_i - length + 1,)
        Distance of each window of ``a`` to its nearest window of ``b`` (inf if ``b`` has none).
    b_min : list of ndarray, one per ``b`` sequence, shape (T_k - length + 1,)
        Distance of each window of ``b`` to its nearest window of ``a``.
    """
    from scipy.spatial.distance import cdist

    A, B = _seq_list(a), _seq_list(b)
    L = int(length)
    if L < 1:
        raise ValueError(f"window length must be >= 1, got {length}")
    a_min = [np.full(max(x.shape[0] - L + 1, 0), np.inf) for x in A]
    b_min = [np.full(max(y.shape[0] - L + 1, 0), np.inf) for y in B]
    step = max(int(block), 1)
    for ia, x in enumerate(A):
        na = x.shape[0] - L + 1
        if na <= 0:
            continue
        for ib, y in enumerate(B):
            nb = y.shape[0] - L + 1
            for k0 in range(0, max(nb, 0), step):
                k1 = min(k0 + step, nb)
                D = cdist(x, y[k0:k1 + L - 1])
                C = D[0:na, 0:k1 - k0].copy()
                for m in range(1, L):
                    C += D[m:m + na, m:m + k1 - k0]
                C /= L
                np.minimum(a_min[ia], C.min(axis=1), out=a_min[ia])
                np.minimum(b_min[ib][k0:k1], C.min(axis=0), out=b_min[ib][k0:k1])
    return a_min, b_min


def window_scores(gen, db, length: int, threshold_m: float) -> dict:
    """:func:`coverage` and :func:`local_diversity` from one pass of :func:`window_nearest`.

    Returns
    -------
    dict
        ``coverage`` (share of database windows covered), ``local_diversity`` (m).
    """
    g_min, d_min = window_nearest(gen, db, length)
    d = np.concatenate([np.zeros(0), *d_min])
    g = np.concatenate([np.zeros(0), *g_min])
    return {
        "coverage": float(np.mean(d < threshold_m)) if d.size and g.size else _NAN,
        "local_diversity": float(g.mean()) if g.size and d.size else _NAN,
    }


def coverage(gen, db, length: int, threshold_m: float) -> float:
    """Share of database windows whose nearest generated window lies closer than ``threshold_m`` (GANimator).

    Parameters
    ----------
    gen : ndarray (T, F) or sequence of them
        Generated feature sequences (:func:`pose_features`); several seeds are pooled.
    db : ndarray (T, F) or sequence of them
        The database clips' features.
    length : int
        Window length (frames).
    threshold_m : float
        Mean frame distance (m) below which a window counts as covered.

    Returns
    -------
    float
        In [0, 1]; NaN when either side has no window.
    """
    return window_scores(gen, db, length, threshold_m)["coverage"]


def local_diversity(gen, db, length: int) -> float:
    """Mean distance (m) of each generated window to its nearest database window (GANimator's local diversity).

    Parameters
    ----------
    gen, db : ndarray (T, F) or sequence of them
    length : int

    Returns
    -------
    float
        0 for a generator that replays database windows; NaN when either side has no window.
    """
    return window_scores(gen, db, length, np.inf)["local_diversity"]


def seed_diversity(features) -> float:
    """Mean distance (m) between the outputs of different seeds from one start, frame by frame.

    ``mean over seed pairs (a, b) of mean_t |f_a(t) - f_b(t)|`` over the frames both have (an average
    pairwise distance in the manner of DLow's APD).

    Parameters
    ----------
    features : sequence of ndarray, each shape (T_s, F)
        :func:`pose_features` of each seed's output.

    Returns
    -------
    float
        0 when every seed gives the same motion; NaN for fewer than two seeds.
    """
    F = _seq_list(features)
    if len(F) < 2:
        return _NAN
    vals = []
    for i in range(len(F)):
        for j in range(i + 1, len(F)):
            n = min(F[i].shape[0], F[j].shape[0])
            vals.append(np.linalg.norm(F[i][:n] - F[j][:n], axis=1).mean())
    return float(np.mean(vals))


def novelty(gen, db, tolerance_m: float) -> dict:
    """Distance of each generated frame to its nearest database frame.

    Parameters
    ----------
    gen : ndarray (T, F) or sequence of them
        Generated :func:`pose_features`.
    db : ndarray (T, F) or sequence of them
        The database's features.
    tolerance_m : float
        A generated frame whose nearest database frame is at most this far (m) counts as a copy.

    Returns
    -------
    dict
        ``novelty_median_m`` (median nearest-frame distance, m), ``copy_share`` (share of generated frames
        that are copies).
    """
    from scipy.spatial import cKDTree

    G, D = _seq_list(gen), _seq_list(db)
    g, d = np.concatenate(G), np.concatenate(D)
    if g.shape[0] == 0 or d.shape[0] == 0:
        return {"novelty_median_m": _NAN, "copy_share": _NAN}
    if g.shape[1] != d.shape[1]:
        raise ValueError(f"generated features have {g.shape[1]} columns, the database's {d.shape[1]}")
    dist, _ = cKDTree(d).query(g, k=1)
    return {"novelty_median_m": float(np.median(dist)), "copy_share": float(np.mean(dist <= tolerance_m))}


# ----------------------------------------------------------------------------- the records' computations


def score_windows(s) -> dict:
    """``coverage`` and ``local_diversity_m`` of the generated frames of ``s`` (a :class:`~.scored.ScoredMotion`)
    against the clip's database: windows of ``compare.metrics.window`` frames (at most the motion's),
    threshold ``coverage_threshold_m``."""
    win = window_scores(s.features, s.ref.features, min(int(s.mcfg["window"]), s.n_frames),
                        s.setting("coverage_threshold_m"))
    return {"coverage": win["coverage"], "local_diversity_m": win["local_diversity"]}


def score_novelty(s) -> dict:
    """``novelty_median_m`` and ``copy_share`` of the generated frames of ``s`` (``compare.metrics.copy_tolerance_m``)."""
    return novelty(s.features, s.ref.features, s.setting("copy_tolerance_m"))


def run_seed_diversity(run) -> dict:
    """``seed_diversity_m`` over every seed of one generator's run on a clip (a :class:`~.scored.RunOutputs`)."""
    return {"seed_diversity_m": seed_diversity(run.features)}


# ----------------------------------------------------------------------------- the records
COVERAGE = Metric("coverage", "share of database windows", "higher", "database", "coverage",
                  "coverage of database windows", exploratory=True, margin=0.05,
                  margin_why="5 % of the database's windows: about one second of a 20-s database reached or missed",
                  compute="windows:score_windows")
#: this module's columns, in their order in ``metrics.csv``
RECORDS = (
    COVERAGE,
    Metric("local_diversity_m", "m", "", "database", compute="windows:score_windows"),
    Metric("seed_diversity_m", "m", "higher", "seeds", title="diversity across seeds (m)",
           compute="windows:run_seed_diversity"),
    Metric("novelty_median_m", "m", "", "database", "novelty (m)", "novelty: distance to nearest database frame (m)",
           margin=0.01, margin_why="1 cm median distance to the nearest database pose: closer, a pose is a copy with "
                                   "capture noise", compute="windows:score_novelty"),
    Metric("copy_share", "share of frames", "", "database", compute="windows:score_novelty"),
)
