"""Smoothness of a motion's speed profile: log dimensionless jerk and spectral arc length."""

from __future__ import annotations

import numpy as np

from .metric_record import Metric

__all__ = ["speed_profile", "ldlj", "sparc", "score_ldlj", "score_sparc", "RECORDS"]

_NAN = float("nan")


def speed_profile(pos, fps: float) -> np.ndarray:
    """Mean joint speed per step (m/s).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)
    fps : float

    Returns
    -------
    ndarray, shape (T-1,)
        ``mean_j |p_j(t) - p_j(t-1)| * fps`` for ``t = 1 .. T-1``.
    """
    pos = np.asarray(pos, float)
    if pos.ndim != 3:
        raise ValueError(f"pos must have shape (T, J, 3), got {pos.shape}")
    return np.linalg.norm(np.diff(pos, axis=0), axis=-1).mean(axis=1) * fps


def _speed(x, fps) -> np.ndarray:
    x = np.asarray(x, float)
    v = speed_profile(x, fps) if x.ndim == 3 else x
    if v.ndim != 1:
        raise ValueError(f"expected a speed profile (N,) or positions (T, J, 3), got shape {x.shape}")
    return v


def ldlj(x, fps: float) -> float:
    """Log dimensionless jerk of a speed profile (Balasubramanian et al. 2015).

    ``LDLJ = -ln( (t2 - t1)^3 / v_peak^2 * integral (d^2 v / dt^2)^2 dt )`` with the second derivative by
    second differences and the integral by the rectangle rule; the duration is ``t2 - t1 = N / fps``, as the
    reference implementation (siva82kb/SPARC ``log_dimensionless_jerk``) takes it. Higher (closer to zero) is
    smoother; a minimum-jerk point-to-point movement gives ``-ln(204.8) = -5.322`` whatever its
    amplitude and duration (the finite differences are off by about ``5 / (duration * fps)``).

    Parameters
    ----------
    x : ndarray, shape (N,) or (T, J, 3)
        A speed profile (m/s) sampled at ``fps``, or positions (then :func:`speed_profile`).
    fps : float

    Returns
    -------
    float
        NaN for a profile of fewer than 3 samples or zero peak speed; +inf when the jerk integral is zero.
    """
    v = _speed(x, fps)
    if v.size < 3:
        return _NAN
    peak = float(np.max(np.abs(v)))
    if peak == 0.0:
        return _NAN
    duration = v.size / fps
    integral = float(np.sum((np.diff(v, 2) * fps * fps) ** 2)) / fps
    if integral == 0.0:
        return float("inf")
    return float(-np.log(duration ** 3 / peak ** 2 * integral))


def sparc(x, fps: float, pad_level: int = 4, cutoff_hz: float = 10.0, amplitude_threshold: float = 0.05) -> float:
    """Spectral arc length of a speed profile (Balasubramanian et al. 2012, 2015).

    The magnitude spectrum of the profile, zero-padded to ``2 ** (ceil(log2 N) + pad_level)`` samples and
    normalised by its value at 0 Hz, is cut at the adaptive frequency ``f_c``: the highest frequency up to
    ``cutoff_hz`` at which it is still at least ``amplitude_threshold``. SPARC is minus the arc length of that
    piece with frequency normalised by ``f_c``. Closer to zero is smoother; it does not change when the profile
    is scaled.

    Parameters
    ----------
    x : ndarray, shape (N,) or (T, J, 3)
        A speed profile (m/s) sampled at ``fps``, or positions (then :func:`speed_profile`).
    fps : float
    pad_level, cutoff_hz, amplitude_threshold
        The method's published parameters (4, 10 Hz, 0.05).

    Returns
    -------
    float
        NaN for fewer than 2 samples, a profile whose mean is zero, or a spectrum below the threshold at every
        frequency above 0 Hz.
    """
    from scipy.fft import fft

    v = _speed(x, fps)
    if v.size < 2:
        return _NAN
    n_fft = int(2 ** (int(np.ceil(np.log2(v.size))) + int(pad_level)))
    mag = np.abs(fft(v, n=n_fft))[: n_fft // 2 + 1]
    if mag[0] == 0.0:
        return _NAN
    mag = mag / mag[0]
    freq = np.arange(mag.size) * fps / n_fft
    inband = np.flatnonzero((freq <= cutoff_hz) & (mag >= amplitude_threshold))
    last = int(inband[-1])
    if last == 0:
        return _NAN
    f, m = freq[: last + 1], mag[: last + 1]
    return float(-np.sum(np.sqrt((np.diff(f) / (f[-1] - f[0])) ** 2 + np.diff(m) ** 2)))


def score_ldlj(s) -> dict:
    """``ldlj`` of the generated frames of ``s`` (a :class:`~.scored.ScoredMotion`)."""
    return {"ldlj": ldlj(s.generated_pos, s.fps)}


def score_sparc(s) -> dict:
    """``sparc`` of the generated frames of ``s``."""
    return {"sparc": sparc(s.generated_pos, s.fps)}


#: this module's columns, in their order in ``metrics.csv``
RECORDS = (
    Metric("ldlj", "log dimensionless jerk", "higher", "", "LDLJ",
           "smoothness: log dimensionless jerk (higher smoother)", compute="smoothness:score_ldlj"),
    Metric("sparc", "spectral arc length", "higher", "", compute="smoothness:score_sparc"),
)
