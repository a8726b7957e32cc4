"""The pose similarity of eq. 3 and its node-to-node form.

For two poses a, b of a region (displacements ``d`` and instantaneous
velocities ``v`` of its landmarks)::

    S(a, b) = sum_l ||d_a,l - d_b,l|| * (1 + lambda * vinfl_l)
    vinfl_l = 1 - |cos(v_a,l, v_b,l)|

``|cos|`` makes a pose and its time-reversed copy (same position, opposite
velocity) similar, which the neutral-peak-neutral samples rely on.

**Zero velocities.** The cosine is undefined when a velocity vanishes (the
first/last frames, the peak of a neutral-peak-neutral sample, landmarks that do
not move). If either speed is at most ``eps`` (px/frame) the landmark carries
no direction information and gets ``vinfl = 0``: it is compared on distance
alone (the most permissive choice, so still poses are never kept apart by
noise in a meaningless direction).

Between two graph nodes the similarity is the minimum of eq. 3 over the
velocities stored for their incoming edges (one mean arrival velocity per
incoming edge), with the node's mean displacement as its position.
"""

from __future__ import annotations

import numpy as np


def vinfl(va: np.ndarray, vb: np.ndarray, eps: float = 1e-2) -> np.ndarray:
    """1 - |cos| of two velocity arrays (..., 2) -> (...); 0 where a speed <= eps."""
    na = np.sqrt((va * va).sum(-1))
    nb = np.sqrt((vb * vb).sum(-1))
    ok = (na > eps) & (nb > eps)
    den = np.where(ok, na * nb, 1.0)
    cos = np.where(ok, (va * vb).sum(-1) / den, 1.0)
    return 1.0 - np.minimum(np.abs(cos), 1.0)


def pose_similarity(da, va, db, vb, lam: float = 1.0, eps: float = 1e-2) -> np.ndarray:
    """Eq. 3 for (broadcastable) arrays of shape (..., L, 2) -> (...)."""
    dist = np.sqrt(((np.asarray(da, float) - np.asarray(db, float)) ** 2).sum(-1))
    return (dist * (1.0 + lam * vinfl(np.asarray(va, float), np.asarray(vb, float), eps))).sum(-1)


def node_similarity(da, vin_a, db, vin_b, lam: float = 1.0, eps: float = 1e-2) -> float:
    """Similarity of two nodes: eq. 3 on their mean displacements ``da, db``
    (L, 2), minimised over their incoming-edge velocities ``vin_a`` (ka, L, 2)
    and ``vin_b`` (kb, L, 2)."""
    dist = np.sqrt(((np.asarray(da, float) - np.asarray(db, float)) ** 2).sum(-1))  # (L,)
    vi = vinfl(np.asarray(vin_a, float)[:, None], np.asarray(vin_b, float)[None, :], eps)  # (ka, kb, L)
    return float((dist * (1.0 + lam * vi)).sum(-1).min())
