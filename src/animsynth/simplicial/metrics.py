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
    if p.shape[0] * a.shape[0] > 4096:  # large inputs: no (m, s, d) temporary (same result, see below)
        return _point_polyline_distance_gemm(p, a, ab, ab2, safe, max_elems)
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


def _point_polyline_distance_gemm(p, a, ab, ab2, safe, max_elems):
    """Large inputs: candidate segment by matrix products, exact distance to it.

    ``|p - a - t ab|^2 = |p - a|^2 - 2 t (p - a).ab + t^2 |ab|^2`` with the dot
    products from two matrix products (centred on the polyline's mean), so no
    (m, s, d) temporary is formed; the closest segment under these values is
    then measured exactly. The result equals the direct formula up to float
    rounding of the squared distances (relative 1e-12 of the squared norms).
    """
    c = a.mean(axis=0)
    pc, ac = p - c, a - c
    a2 = np.einsum("sd,sd->s", ac, ac)
    a_ab = np.einsum("sd,sd->s", ac, ab)
    out = np.empty(p.shape[0])
    chunk = max(1, int(max_elems // max(a.shape[0], 1)))
    for lo in range(0, p.shape[0], chunk):
        q = pc[lo:lo + chunk]
        q2 = np.einsum("md,md->m", q, q)
        ap_ab = q @ ab.T - a_ab[None, :]  # (p - a).ab
        ap2 = q2[:, None] - 2.0 * (q @ ac.T) + a2[None, :]  # |p - a|^2
        t = np.clip(ap_ab / safe, 0.0, 1.0)
        t[:, ab2 == 0] = 0.0
        d2 = ap2 - 2.0 * t * ap_ab + t * t * ab2[None, :]
        j = np.argmin(d2, axis=1)
        tj = t[np.arange(len(j)), j]
        diff = q - ac[j] - tj[:, None] * ab[j]
        out[lo:lo + chunk] = np.sqrt(np.einsum("md,md->m", diff, diff))
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
