"""Error A and Error F of Gauch & Peters, plus point-to-polyline distances.

Error A
    The mean distance from every true (held-out) point to the closest point on
    the generated polyline, and the mean distance from every generated point
    to the closest point on the true polyline, averaged over both directions:
    ``A = (mean_t d(t, G) + mean_g d(g, T)) / 2``.
Error F
    The closest approach of the generated polyline to the true final point:
    ``F = d(T_last, G)``.

Both are in latent units. ``*_norm`` variants divide by the diagonal of the
fold's latent bounding box (training points of that fold), so that subsets
with differently spread latent spaces compare.
"""

from __future__ import annotations

import numpy as np


def point_polyline_distance(points, polyline, max_elems: int = 4_000_000) -> np.ndarray:
    """Distance from every point to the closest point of a polyline (vectorised).

    Parameters
    ----------
    points : array (m, d)
    polyline : array (n, d); a single vertex is treated as a point.
    max_elems : int
        Work in chunks of points so that no temporary exceeds this many floats.

    Returns
    -------
    ndarray (m,)
    """
    p = np.atleast_2d(np.asarray(points, float))
    line = np.atleast_2d(np.asarray(polyline, float))
    if line.shape[0] == 0:
        raise ValueError("polyline is empty")
    if line.shape[0] == 1:
        return np.linalg.norm(p - line[0], axis=1)
    a = line[:-1]
    ab = line[1:] - a
    ab2 = np.einsum("sd,sd->s", ab, ab)
    safe = np.where(ab2 > 0, ab2, 1.0)
    out = np.empty(p.shape[0])
    chunk = max(1, int(max_elems // max(a.shape[0] * a.shape[1], 1)))  # bounds memory in high dimension
    for lo in range(0, p.shape[0], chunk):
        q = p[lo:lo + chunk]
        ap = q[:, None, :] - a[None, :, :]  # (m, s, d)
        t = np.clip(np.einsum("msd,sd->ms", ap, ab) / safe, 0.0, 1.0)
        t[:, ab2 == 0] = 0.0
        diff = ap - t[..., None] * ab[None]
        out[lo:lo + chunk] = np.sqrt(np.einsum("msd,msd->ms", diff, diff).min(axis=1))
    return out


def error_a(true, generated) -> tuple[float, float, float]:
    """Error A and its two directions.

    Returns
    -------
    (A, true_to_generated, generated_to_true)
    """
    t2g = float(point_polyline_distance(true, generated).mean())
    g2t = float(point_polyline_distance(generated, true).mean())
    return 0.5 * (t2g + g2t), t2g, g2t


def error_f(true, generated) -> float:
    """Closest approach of the generated polyline to the true final point."""
    true = np.atleast_2d(np.asarray(true, float))
    return float(point_polyline_distance(true[-1:], generated)[0])
