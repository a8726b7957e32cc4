"""One call from a capture to a re-sequenced motion (CLI, notebooks): explicit keyword arguments instead of the
workflow's config block, the same estimator as the workflow steps (:mod:`.jobs`) and the comparison
(:class:`~.generator.Resequencer`)."""

from __future__ import annotations

import numpy as np

from ..generator import play_path
from ..motion import Motion
from .generator import Resequencer
from .paths import pad_path, resolve_frame

__all__ = ["resequence_motion"]


def resequence_motion(motion: Motion, start: int, end: int, method: str = "stisomap", metric: str = "l2",
                      k: int | None = None, global_dof: bool = False, length: int | None = None, *,
                      sign_mode: str = "continuous", lee: dict | None = None, st: dict | None = None,
                      root_playback: str = "integrate") -> tuple[np.ndarray, Motion]:
    """One-call re-sequencing (CLI, notebooks): Dijkstra from ``start`` to ``end``.

    Parameters
    ----------
    motion : Motion
        The capture, ``(frames, dof)`` values.
    start, end : int
        First and last frame of the path (negative counts from the end).
    method : {"stisomap", "st-isomap", "isomap"}
    metric : {"l2", "lee"}
    k : int, optional
        Neighbours; default the smallest k giving one connected component of the method's graph
        (:class:`~.generator.Resequencer` with ``neighbours="dense"`` builds the graph and the path).
    global_dof : bool
        Include the root translation and orientation in the distances.
    length : int, optional
        Pad the path to this many frames (holding the last frame).
    sign_mode : str
        Quaternion linearisation of the L2 features (:func:`.features.linearize_quaternions`).
    lee : dict, optional
        Keyword arguments of :func:`.distances.lee_distances` (``weights``, ``nu``, ``sqrt``,
        ``translation_scale``); its defaults (the paper's weights) otherwise.
    st : dict, optional
        Keyword arguments of :func:`.embedding.spatio_temporal_distances` (in frames); its defaults otherwise.
    root_playback : {"integrate", "absolute"}
        Root of the played motion (:func:`animsynth.generator.play_path`).

    Returns
    -------
    path : int array (frames,)
        The frame index path (padded to ``length`` if given).
    played : Motion
        The motion it plays.
    """
    method = {"st-isomap": "stisomap"}.get(method, method)
    n = motion.n_frames
    a, b = resolve_frame(start, n, "start"), resolve_frame(end, n, "end")
    est = Resequencer(method, k=None if k is None else int(k), neighbours="dense", metric=metric,
                      global_dof=global_dof, sign_mode=sign_mode, lee=lee, st=st).fit([motion])
    path = pad_path(est.path(a, b), length, "hold")
    return path, play_path(motion, path, root=root_playback, name="resequenced")
