"""Re-sequencing: shortest-cost paths on the neighbourhood graph (the motion a path plays is
:func:`animsynth.generator.play_path`, where every generator plays its frame paths)."""

from __future__ import annotations

import numpy as np
from scipy.sparse.csgraph import dijkstra

from .embedding import DisconnectedGraphError

__all__ = ["shortest_path_frames", "pad_path", "resolve_frame"]


def resolve_frame(spec, n: int, what: str = "frame") -> int:
    """A frame index from an int (negative counts from the end) or a float fraction in [0, 1]."""
    if isinstance(spec, bool):
        raise ValueError(f"{what}: expected an int or a fraction, got {spec!r}")
    if isinstance(spec, float):
        if not 0.0 <= spec <= 1.0:
            raise ValueError(f"{what}: fraction {spec} outside [0, 1]")
        return int(round(spec * (n - 1)))
    i = int(spec)
    if i < 0:
        i += n
    if not 0 <= i < n:
        raise ValueError(f"{what}: index {spec} outside a motion of {n} frames")
    return i


def shortest_path_frames(graph, start: int, end: int) -> tuple[np.ndarray, float]:
    """Dijkstra shortest-cost path from ``start`` to ``end`` on an undirected weighted graph.

    Returns
    -------
    path : int array of frame indices, ``path[0] == start``, ``path[-1] == end``
    cost : float, sum of the edge weights along the path

    Raises
    ------
    DisconnectedGraphError if ``end`` cannot be reached.
    """
    n = graph.shape[0]
    for name, v in (("start", start), ("end", end)):
        if not 0 <= int(v) < n:
            raise ValueError(f"{name} frame {v} outside 0..{n - 1}")
    dist, pred = dijkstra(graph, directed=False, indices=int(start), return_predecessors=True)
    if not np.isfinite(dist[end]):
        raise DisconnectedGraphError(f"frame {end} is not reachable from frame {start}")
    path = [int(end)]
    while path[-1] != start:
        path.append(int(pred[path[-1]]))
    return np.asarray(path[::-1], dtype=np.int64), float(dist[end])


def pad_path(path, length: int | None, mode: str = "hold") -> np.ndarray:
    """Pad a frame-index path to ``length`` frames (``None``: unchanged).

    ``mode="hold"`` repeats the last frame; ``"reverse"`` plays the path back
    and forth (ping-pong) until the length is reached. A path already at least
    ``length`` long is returned unchanged (never truncated).
    """
    path = np.asarray(path, dtype=np.int64)
    if length is None or len(path) >= length:
        return path
    extra = int(length) - len(path)
    if mode == "hold":
        return np.concatenate([path, np.full(extra, path[-1])])
    if mode == "reverse":
        if len(path) < 2:
            return np.concatenate([path, np.full(extra, path[-1])])
        cycle = np.concatenate([path[-2::-1], path[1:]])
        reps = int(np.ceil(extra / len(cycle)))
        return np.concatenate([path, np.tile(cycle, reps)[:extra]])
    raise ValueError(f"unknown padding mode {mode!r} (hold, reverse)")
