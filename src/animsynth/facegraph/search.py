"""Threshold search for a target compression (paper section 4.3, step halving).

The compression a threshold gives is only known by building the graph, and it
grows with the threshold. The search walks the threshold towards the target:

* start at ``t0`` with step ``step0``;
* build, measure the compression ``c``; stop when ``|c - target| <= tol``;
* if ``c < target`` raise the threshold by the step, else lower it;
* whenever the direction reverses (the compression passed the target band)
  halve the step; a step that would make the threshold negative is halved
  until it does not;
* stop (not converged) when the step falls below ``min_step``.

It runs element-wise on arrays (one threshold per region) so the creation
search of all regions shares one vectorised build per iteration. If the
target is not reached within ``max_iter`` builds (compression is a step
function of the threshold, so a narrow tolerance can be impossible) the
closest threshold seen is returned with ``converged = False``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class SearchResult:
    threshold: np.ndarray
    compression: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    history: list = field(default_factory=list)  # (iteration, thresholds, compressions)


def step_halving_search(evaluate, target: float, tol: float, t0, step0, max_iter: int = 40,
                        min_step=0.0) -> SearchResult:
    """Find thresholds whose compression (``evaluate(T) -> array``, in %) is
    within ``tol`` of ``target`` (%). ``t0``/``step0``/``min_step``: arrays or
    scalars (one element per independent search)."""
    T = np.atleast_1d(np.asarray(t0, float)).copy()
    step = np.broadcast_to(np.atleast_1d(np.asarray(step0, float)), T.shape).copy()
    min_step = np.broadcast_to(np.asarray(min_step, float), T.shape)
    if np.any(T < 0) or np.any(step <= 0):
        raise ValueError("t0 must be >= 0 and step0 > 0")
    prev_dir = np.zeros(T.shape, int)
    done = np.zeros(T.shape, bool)
    best_T = T.copy()
    best_c = np.full(T.shape, np.nan)
    best_err = np.full(T.shape, np.inf)
    iters = np.zeros(T.shape, int)
    history = []
    for it in range(1, max_iter + 1):
        c = np.asarray(evaluate(T.copy()), float)
        history.append((it, T.copy(), c.copy()))
        active = ~done
        iters[active] = it
        err = np.abs(c - target)
        better = active & (err < best_err)
        best_T[better], best_c[better], best_err[better] = T[better], c[better], err[better]
        done |= active & (err <= tol)
        if done.all():
            break
        direction = np.where(c < target, 1, -1)
        flip = active & (prev_dir != 0) & (direction != prev_dir)
        step[flip] /= 2.0
        done |= active & (step < min_step)
        if done.all():
            break
        move = active & ~done
        for i in np.flatnonzero(move):
            while T[i] + direction[i] * step[i] < 0:
                step[i] /= 2.0
                if step[i] < 1e-12:
                    break
            T[i] = max(T[i] + direction[i] * step[i], 0.0)
        prev_dir = np.where(move, direction, prev_dir)
    return SearchResult(best_T, best_c, iters, best_err <= tol, history)
