"""Pre-processing of landmarked expression sequences (paper section 4.1).

Steps, per labelled neutral-to-peak sequence (sample):

1. **Procrustes, stage 1 (rigid).** Every frame is aligned to the sample's
   first frame by a rotation + translation fitted on the nose bridge and eye
   corners (head motion removed, expression kept).
2. **Sigmoid fit (eq. 1-2).** The displacement of every landmark from the
   first (neutral) frame, ``d(t) = p(t) - p(0)`` (eq. 2), is fitted with
   ``d(t) ~ a + b / (1 + exp(-k (t - c)))`` (eq. 1; per landmark the x and y
   displacements share the timing k, c) by ``scipy.optimize.curve_fit``'s
   Levenberg-Marquardt fit (its result, computed by calling ``leastsq``
   directly: :func:`_sigmoid_xy_fit`) started from the best point of a (c, k)
   grid; the landmark becomes ``p(0) + fit(t)``. This removes tracking jitter
   and keeps the neutral-to-peak onset shape. Fallbacks (counted, logged and stored in
   :attr:`FacePreprocessor.report_`): a landmark whose displacement varies by
   less than ``sigmoid_min_range_px`` is *static* and replaced by
   ``p(0) + mean(d)``; when curve_fit fails, does not improve on its grid
   start or returns a step steeper than the grid's steepest onset (jitter of a
   nearly still landmark), the grid sigmoid is kept.

   *Order.* The paper lists the sigmoid fit first. Fitting before the rigid
   alignment lets head motion leak into the fit (a sigmoid cannot follow a
   head drift: a 4 degree drift leaves errors of ~2.5 px, see
   tests/test_facegraph.py), so by default stage 1 runs first;
   ``align_before_fit=False`` gives the literal order.
3. **Reduced landmark set.** The similarity metric uses a reduced set per
   region (:mod:`.regions`); every landmark is kept in the data.
4. **Procrustes, stage 2 (per region).** For each region, the first pose is
   aligned (rotation, uniform scale, translation) to the *mean neutral* (the
   generalised-Procrustes mean of all first poses, at image scale) and the
   same transform is applied to all of the sample's poses (identity placement
   and size removed per region).
5. Poses become displacements from the sample's own first pose, and a
   **reversed copy** is appended (without repeating the peak) so every sample
   goes neutral -> peak -> neutral (``2F - 1`` poses); velocities are central
   differences (one-sided at the ends), so the peak pose has zero velocity.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import leastsq
from scipy.special import expit

from ..atomic import atomic_path
from ..io.ckplus import EMOTIONS, CKSequence
from .geometry import apply_transform_2d, fit_transform_2d
from .regions import REGION_NAMES, check_regions

log = logging.getLogger("animsynth.facegraph.preprocess")


def sigmoid(t, a, b, k, c):
    """Eq. 1: ``a + b / (1 + exp(-k (t - c)))``."""
    return a + b * expit(k * (np.asarray(t, float) - c))


_LM_SUCCESS = (1, 2, 3, 4)  # MINPACK's converged codes; curve_fit raises RuntimeError on any other


def _sigmoid_xy_fit(t: np.ndarray, y: np.ndarray, p0, jac: np.ndarray) -> np.ndarray:
    """Levenberg-Marquardt refinement of one landmark's eq.-1 fit; the result is ``curve_fit``'s.

    ``y`` is the landmark's x displacements then its y displacements at frames ``t`` (2n values), ``p0`` the start
    (ax, ay, bx, by, k, c): x and y have their own offset a and amplitude b and share the timing (k, c).
    Returns the parameters that ``scipy.optimize.curve_fit(model, [t, t], y, p0=p0, jac=jacobian, maxfev=400)``
    (method 'lm') returns for eq. 1, bit for bit, and raises as it does where it matters here: ValueError when
    ``y`` is not finite, RuntimeError when MINPACK does not converge (``ier`` not in 1-4: maxfev reached or a
    tolerance too small). ``jac`` is a preallocated (2n, 6) buffer holding the Jacobian's constant columns
    (d/dax, d/day: ones in the x rows, resp. the y rows, zeros elsewhere); its other entries are rewritten
    on every call.

    ``scipy.optimize.leastsq`` is called directly: curve_fit's wrappers (memoiser, input checks) and the
    covariance it computes on every call (``full_output``) cost about as much as the fit itself here, and the
    covariance is discarded. The residual is curve_fit's (model minus data) with the same arithmetic per element,
    the Jacobian has the same entries computed in the same operation order, and leastsq gets the same start,
    ``maxfev`` and default tolerances, so MINPACK takes the same steps (tests/test_facegraph.py compares the
    two on real-shaped landmarks). Residual and Jacobian at one parameter vector share ``t - c`` and the
    sigmoid (MINPACK mostly asks for the Jacobian where it last evaluated the residual): the same floats,
    computed once.
    """
    y = np.asarray_chkfinite(y, float)  # curve_fit's input check (ValueError on NaN/inf)
    n = t.size
    y2 = y.reshape(2, n)
    jv = jac.reshape(2, n, 6)  # view: [0] the x rows, [1] the y rows
    jx_bx, jy_by, j_k, j_c = jv[0, :, 2], jv[1, :, 3], jv[:, :, 4], jv[:, :, 5]
    last = [None, None, None]  # parameter bytes, t - c, sigmoid

    def timing(p):
        key = p.tobytes()
        if key != last[0]:
            tc = t - p[5]
            last[:] = key, tc, expit(p[4] * tc)
        return last[1], last[2]

    def residual(p):
        # (a + b * s) - y per element, x rows then y rows: curve_fit's model minus data; a new array on every
        # call (leastsq keeps the first one as its residual workspace)
        _, s = timing(p)
        return (p[:2, None] + p[2:4, None] * s - y2).reshape(-1)

    def jacobian(p):
        # d/dbx = s, d/dk = b * ds * (t - c), d/dc = -b * ds * k (products left to right), ds = s * (1 - s);
        # (b * ds) * (-k) is (-b * ds) * k exactly: IEEE rounding is symmetric in the sign
        tc, s = timing(p)
        ds = s * (1.0 - s)
        bds = p[2:4, None] * ds
        np.copyto(jx_bx, s)
        np.copyto(jy_by, s)
        np.multiply(bds, tc, out=j_k)
        np.multiply(bds, -p[4], out=j_c)
        return jac  # leastsq copies it

    # m = 2n >= 8 residuals > 6 parameters and positive tolerances: leastsq's "improper input" (ier 0,
    # a TypeError with full_output=False) cannot occur
    popt, ier = leastsq(residual, np.array(p0, float), Dfun=jacobian, maxfev=400)
    if ier not in _LM_SUCCESS:
        raise RuntimeError(f"Optimal parameters not found (MINPACK ier={ier})")
    return popt


def _sigmoid_xy_jac_buffer(n: int) -> np.ndarray:
    """(2n, 6) Jacobian buffer for :func:`_sigmoid_xy_fit` with its constant columns filled."""
    jac = np.zeros((2 * n, 6))
    jac[:n, 0] = 1.0
    jac[n:, 1] = 1.0
    return jac


_GRID_C = np.linspace(-0.2, 1.2, 29)
_GRID_K = np.array([2.0, 3.0, 4.5, 6.5, 9.0, 13.0, 18.0, 26.0, 40.0])


def sigmoid_grid_fit(d: np.ndarray):
    """Best eq.-1 fit of landmark displacements ``d`` (n, L, 2) on a (c, k) grid
    with exact amplitudes (variable projection); shared timing per landmark.

    Returns (a (L, 2), b (L, 2), k (L,), c (L,)) in frame units.
    """
    n = d.shape[0]
    t = np.arange(n, dtype=float)
    cs = _GRID_C * (n - 1)
    ks = _GRID_K / max(n - 1, 1)
    S = expit(ks[None, :, None] * (t[None, None, :] - cs[:, None, None])).reshape(-1, n)
    Sc = S - S.mean(1, keepdims=True)
    sss = (Sc ** 2).sum(1)
    Y = d.reshape(n, -1)
    Yc = Y - Y.mean(0)
    ssy = Sc @ Yc                                          # (J, L*2)
    score = (ssy ** 2 / sss[:, None]).reshape(len(S), -1, 2).sum(-1)  # (J, L)
    j = score.argmax(0)
    L = d.shape[1]
    b = ssy.reshape(len(S), L, 2)[j, np.arange(L)] / sss[j][:, None]
    a = Y.mean(0).reshape(L, 2) - b * S[j].mean(1)[:, None]
    kk = np.tile(ks, len(cs))[j]
    cc = np.repeat(cs, len(ks))[j]
    return a, b, kk, cc


def fit_sigmoid_landmarks(d: np.ndarray, min_range: float = 1.0) -> tuple[np.ndarray, list[str]]:
    """Fit eq. 1 to the displacement (eq. 2) of every landmark of one sample.

    Parameters
    ----------
    d : ndarray (n, L, 2)
        Displacements from the first frame.
    min_range : float
        A landmark whose displacement magnitude varies by less than this
        (pixels) is *static*: replaced by its mean displacement.

    Returns
    -------
    fitted : ndarray (n, L, 2)
    status : list of ``"fit"`` (curve_fit), ``"static"`` or ``"grid"`` (curve_fit
        failed, did not improve on its start, or fitted an onset steeper than
        the grid's steepest, ``k > 40 / (n - 1)``, i.e. a step fitted to noise;
        the best grid sigmoid is kept).

    Each landmark's x and y displacements share one timing (k, c) and have
    their own offset and amplitude; ``scipy.optimize.curve_fit`` refines the
    best point of a (c, k) grid with exact amplitudes.
    """
    d = np.asarray(d, float)
    n, L, _ = d.shape
    if n < 4:
        raise ValueError(f"a sigmoid fit needs at least 4 frames, got {n}")
    t = np.arange(n, dtype=float)
    jac = _sigmoid_xy_jac_buffer(n)
    a, b, k, c = sigmoid_grid_fit(d)
    k_max = _GRID_K[-1] / max(n - 1, 1)
    out = np.empty_like(d)
    status = []
    for i in range(L):
        di = d[:, i]
        if np.ptp(np.sqrt((di ** 2).sum(-1))) < min_range and np.ptp(di, axis=0).max() < min_range:
            out[:, i] = di.mean(0)
            status.append("static")
            continue
        grid_y = a[i] + b[i] * expit(k[i] * (t - c[i]))[:, None]
        p0 = (a[i, 0], a[i, 1], b[i, 0], b[i, 1], k[i], c[i])
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                popt = _sigmoid_xy_fit(t, np.concatenate([di[:, 0], di[:, 1]]), p0, jac)
            y = sigmoid(t, popt[:2, None], popt[2:4, None], popt[4], popt[5]).T  # eq. 1, x and y rows
            steep_ok = abs(popt[4]) <= k_max
            if steep_ok and np.all(np.isfinite(y)) and ((y - di) ** 2).sum() <= ((grid_y - di) ** 2).sum() + 1e-9:
                out[:, i] = y
                status.append("fit")
                continue
        except (RuntimeError, ValueError):
            pass
        out[:, i] = grid_y
        status.append("grid")
    return out, status


@dataclass
class FaceDatabase:
    """Pre-processed samples (aligned, displacement form).

    Attributes
    ----------
    names : list of str            ``"S005_001"`` per sample
    emotions : ndarray (S,) int     CK+ emotion code of each sample
    lengths : ndarray (S,) int      forward (neutral -> peak) frame counts F
    disp : ndarray (sum F, 68, 2)   forward displacements from each sample's first pose
    neutral : ndarray (S, 68, 2)    aligned first pose of each sample
    mean_neutral : ndarray (68, 2)  mean neutral face (image scale)
    regions, reduced : dict name -> int array of landmark ids
    source : str                    where the data came from (e.g. "synthetic CK+-layout")
    """

    names: list
    emotions: np.ndarray
    lengths: np.ndarray
    disp: np.ndarray
    neutral: np.ndarray
    mean_neutral: np.ndarray
    regions: dict
    reduced: dict
    source: str = ""
    report: dict = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return len(self.names)

    @property
    def offsets(self) -> np.ndarray:
        return np.concatenate([[0], np.cumsum(self.lengths)])

    def forward(self, s: int) -> np.ndarray:
        """(F, 68, 2) neutral -> peak displacements of sample ``s``."""
        o = self.offsets
        return self.disp[o[s]:o[s + 1]]

    def npn(self, s: int) -> tuple[np.ndarray, np.ndarray]:
        """Neutral -> peak -> neutral displacements (2F-1, 68, 2) and velocities."""
        f = self.forward(s)
        x = np.concatenate([f, f[-2::-1]], axis=0)
        return x, np.gradient(x, axis=0) if len(x) > 1 else np.zeros_like(x)

    def label_names(self) -> list[str]:
        return [EMOTIONS[e] for e in self.emotions]

    # -- storage ---------------------------------------------------------
    def save_npz(self, path) -> None:
        arrays = {
            "names": np.array(self.names),
            "emotions": self.emotions,
            "lengths": self.lengths,
            "disp": self.disp,
            "neutral": self.neutral,
            "mean_neutral": self.mean_neutral,
            "source": np.array(self.source),
            "report": np.array(repr(sorted(self.report.items()))),
        }
        for r in REGION_NAMES:
            arrays[f"region_{r}"] = self.regions[r]
            arrays[f"reduced_{r}"] = self.reduced[r]
        with atomic_path(path, suffix=".npz") as tmp:
            np.savez_compressed(tmp, **arrays)

    @classmethod
    def load_npz(cls, path) -> "FaceDatabase":
        with np.load(path, allow_pickle=False) as z:
            return cls(
                names=[str(n) for n in z["names"]],
                emotions=np.array(z["emotions"], int),
                lengths=np.array(z["lengths"], int),
                disp=np.array(z["disp"], float),
                neutral=np.array(z["neutral"], float),
                mean_neutral=np.array(z["mean_neutral"], float),
                regions={r: np.array(z[f"region_{r}"], int) for r in REGION_NAMES},
                reduced={r: np.array(z[f"reduced_{r}"], int) for r in REGION_NAMES},
                source=str(z["source"]),
            )


def _gpa_mean(shapes: np.ndarray, iterations: int = 10) -> np.ndarray:
    """Generalised Procrustes mean of (n, 68, 2) shapes, at their mean size and place."""
    centroid = shapes.mean((0, 1))
    size = np.sqrt(((shapes - shapes.mean(1, keepdims=True)) ** 2).sum((1, 2))).mean()
    ref = shapes[0] - shapes[0].mean(0)
    aligned = shapes
    for _ in range(iterations):
        R, s, t = fit_transform_2d(shapes, np.broadcast_to(ref, shapes.shape), scale=True)
        aligned = apply_transform_2d(shapes, R, s, t)
        new = aligned.mean(0)
        new = new - new.mean(0)
        new *= size / np.sqrt((new ** 2).sum())
        if np.allclose(new, ref, atol=1e-9):
            break
        ref = new
    return ref + centroid


class FacePreprocessor:
    """Sigmoid fit, two-stage Procrustes alignment and displacement form.

    Parameters
    ----------
    regions, reduced : dict or None
        Region -> landmark ids (None: :data:`.regions.DEFAULT_REGIONS` /
        ``DEFAULT_REDUCED``).
    rigid_landmarks : list of int or None
        Stage-1 alignment landmarks (None: nose bridge + eye corners).
    sigmoid_min_range_px : float
        Coordinates moving less than this (pixels) are treated as static.
    min_frames : int
        Labelled sequences shorter than this are skipped (logged).
    max_sequences : int or None
        Use only the first ``max_sequences`` labelled sequences (sorted by name).
    align_before_fit : bool
        Run the stage-1 rigid alignment before the sigmoid fit (default; see
        the module docs) or after it (the paper's listing order).
    """

    def __init__(self, regions=None, reduced=None, rigid_landmarks=None, sigmoid_min_range_px: float = 1.0,
                 min_frames: int = 5, max_sequences: int | None = None, align_before_fit: bool = True):
        self.regions = regions
        self.reduced = reduced
        self.rigid_landmarks = rigid_landmarks
        self.sigmoid_min_range_px = sigmoid_min_range_px
        self.min_frames = min_frames
        self.max_sequences = max_sequences
        self.align_before_fit = align_before_fit

    def fit_transform(self, sequences: list[CKSequence], source: str = "") -> FaceDatabase:
        regions, reduced, rig = check_regions(self.regions, self.reduced, self.rigid_landmarks)
        if self.min_frames < 4:
            raise ValueError("min_frames must be >= 4 (the sigmoid has 4 parameters)")
        seqs = sorted((s for s in sequences if s.emotion is not None), key=lambda s: s.name)
        short = [s.name for s in seqs if s.n_frames < self.min_frames]
        if short:
            log.warning("skipping %d labelled sequence(s) shorter than %d frames: %s", len(short),
                        self.min_frames, short[:10])
        seqs = [s for s in seqs if s.n_frames >= self.min_frames]
        if self.max_sequences is not None:
            seqs = seqs[: int(self.max_sequences)]
        if len(seqs) < 2:
            raise ValueError(f"need at least 2 labelled sequences of >= {self.min_frames} frames, found {len(seqs)}")

        def rigid(p):
            R, sc, t = fit_transform_2d(p[:, rig], np.broadcast_to(p[0, rig], p[:, rig].shape), scale=False)
            return apply_transform_2d(p, R, sc, t)

        counts = {"fit": 0, "static": 0, "grid": 0}
        per_seq: dict[str, dict] = {}
        aligned = []
        for s in seqs:
            lm = np.asarray(s.landmarks, float)
            if not np.all(np.isfinite(lm)):
                raise ValueError(f"sequence {s.name}: non-finite landmark coordinates")
            if self.align_before_fit:
                lm = rigid(lm)
            y, status = fit_sigmoid_landmarks(lm - lm[0], self.sigmoid_min_range_px)
            for st in status:
                counts[st] += 1
            per_seq[s.name] = {k: status.count(k) for k in ("fit", "grid", "static")}
            p = lm[0] + y
            aligned.append(p if self.align_before_fit else rigid(p))
        if counts["grid"]:
            log.warning("%d landmark fits keep the best grid sigmoid (same eq. 1): curve_fit failed, did not "
                        "improve on it, or fitted a step steeper than the grid's steepest onset (jitter of a "
                        "nearly still landmark)", counts["grid"])
        log.info("sigmoid fits: %s", counts)
        for s, p in zip(seqs, aligned):
            if not np.all(np.isfinite(p)) or np.abs(p).max() > 1e6:
                raise ValueError(f"sequence {s.name}: pre-processing produced non-finite or huge coordinates "
                                 f"(input range {np.abs(s.landmarks).max():.3g} px)")
        first = np.stack([p[0] for p in aligned])
        mean_neutral = _gpa_mean(first)
        # stage 2: per region, first pose -> mean neutral (similarity), applied to all poses
        for k, p in enumerate(aligned):
            for name in REGION_NAMES:
                idx = regions[name]
                R, sc, t = fit_transform_2d(p[0, idx], mean_neutral[idx], scale=True)
                p[:, idx] = apply_transform_2d(p[:, idx], R, sc, t)
            aligned[k] = p
        neutral = np.stack([p[0] for p in aligned])
        disp = np.concatenate([p - p[0] for p in aligned], axis=0)
        n_fit = max(1, counts["fit"] + counts["grid"])
        self.report_ = dict(counts, n_sequences=len(seqs), n_skipped_short=len(short),
                            grid_fallback_share=round(counts["grid"] / n_fit, 4))
        self.mean_neutral_ = mean_neutral
        self.sigmoid_status_ = per_seq  # sequence name -> landmark counts per fit status
        return FaceDatabase(
            names=[s.name for s in seqs],
            emotions=np.array([s.emotion for s in seqs], int),
            lengths=np.array([s.n_frames for s in seqs], int),
            disp=disp,
            neutral=neutral,
            mean_neutral=mean_neutral,
            regions=regions,
            reduced=reduced,
            source=source,
            report=dict(self.report_),
        )
