"""Re-sequencing: shortest-cost paths on the neighbourhood graph and the motion they play."""

from __future__ import annotations

import numpy as np
from scipy.sparse.csgraph import dijkstra
from scipy.spatial.transform import Rotation

from ..motion import Motion
from ..kinematics import local_rotations, root_translation, rotation_heading, set_root, wrap_radians
from .embedding import DisconnectedGraphError

__all__ = ["shortest_path_frames", "pad_path", "play_path", "resolve_frame"]


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


def play_path(motion: Motion, path, root: str = "integrate", name: str | None = None, same_pass: int = 1) -> Motion:
    """The motion a frame-index path plays.

    Joint angles are those of the path's frames. The root:

    * ``"absolute"``: the frames' own root position and orientation (the
      character teleports when the path jumps between distant frames).
    * ``"integrate"``: root motion is re-integrated. Each step ``a -> b`` moves
      the root by the original displacement ``p[b] - p[a]`` and turns it by the
      original heading change when ``1 <= |b - a| <= same_pass`` (a step within
      the same pass of the capture, forward *or backward*, possibly skipping
      frames); after a jump to another pass it uses frame ``b``'s own step
      ``b-1 -> b``.
      Displacements are expressed in the heading frame (rotation about Y), so
      they follow the accumulated heading; the height is frame ``b``'s own.

    Returns a :class:`Motion` on the same skeleton and frame rate.
    """
    path = np.asarray(path, dtype=np.int64)
    sk = motion.skeleton
    vals = np.asarray(motion.values, float)
    n = vals.shape[0]
    if path.size == 0 or path.min() < 0 or path.max() >= n:
        raise ValueError(f"path indices must lie in 0..{n - 1}")
    out = vals[path].copy()
    if root not in ("absolute", "integrate"):
        raise ValueError(f"root must be 'absolute' or 'integrate', got {root!r}")
    if root == "integrate" and path.size > 1:
        R0 = local_rotations(sk, vals)[0]
        p = root_translation(sk, vals)
        yaw = rotation_heading(R0)
        m = path.size
        new_yaw = np.empty(m)
        new_p = np.empty((m, 3))
        new_yaw[0] = yaw[path[0]]
        new_p[0] = p[path[0]]
        for t in range(1, m):
            a, b = int(path[t - 1]), int(path[t])
            if 1 <= abs(b - a) <= max(1, int(same_pass)):
                src, dst = a, b
            elif b > 0:
                src, dst = b - 1, b
            else:
                src, dst = b, b  # first frame reached by a jump: no step information
            dyaw = wrap_radians(yaw[dst] - yaw[src])
            d = p[dst] - p[src]
            c, s = np.cos(-yaw[src]), np.sin(-yaw[src])
            local = np.array([c * d[0] + s * d[2], -s * d[0] + c * d[2]])  # R_y(-yaw) on (x, z)
            c2, s2 = np.cos(new_yaw[t - 1]), np.sin(new_yaw[t - 1])
            new_p[t, 0] = new_p[t - 1, 0] + c2 * local[0] + s2 * local[1]
            new_p[t, 2] = new_p[t - 1, 2] - s2 * local[0] + c2 * local[1]
            new_p[t, 1] = p[b, 1]
            new_yaw[t] = new_yaw[t - 1] + dyaw
        # new root rotation = R_y(new_yaw - yaw[b]) * R[b]
        Ry = Rotation.from_euler("y", (new_yaw - yaw[path])[:, None])
        out = set_root(sk, out, Ry * R0[path], new_p)
    return Motion(out, sk, motion.fps, name or f"{motion.name}_reseq", dict(motion.meta))
