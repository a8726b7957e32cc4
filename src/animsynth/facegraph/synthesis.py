"""Synthesis from expression labels on region motion graphs (paper section 5).

For every requested label, in every region graph:

* a **random valid peak node** is chosen: a node where a database sample of
  that label peaks and that is reachable from the current node (seeded
  generator);
* **Dijkstra** (``scipy.sparse.csgraph.dijkstra``, edge weight = eq. 3
  similarity) gives the path from the current node (the neutral node, or the
  previous label's peak) to it. If no peak node of the label is reachable
  from the current node (a graph whose neutral nodes did not all merge is not
  strongly connected), the region restarts from the neutral node - a node
  holding some sample's first pose - that reaches one (the one most samples
  start from); this fallback is logged and listed in ``Animation.jumps``;
* optional **coherent noise** replaces a share of the interior path nodes by
  random nodes within ``noise_hops`` hops (undirected) that share a label with
  the node they replace.

**Motion recovery.**

1. *Velocity-based pose expansion with clamping.* Each path node ``k``
   becomes ``round(mean consecutive-merge count)`` frames centred on its mean
   displacement (the node's centre), spaced by the node's mean landmark speed
   along the direction to the next path node; each landmark's offset is
   clamped to half the distance to the neighbouring path node, so no frame
   passes the midpoint between two nodes.
2. *Duration from the peak node.* Each peak node stores the neutral-to-peak
   durations of the samples peaking in it (mean and spread). A segment ending
   in peak node(s) is stretched (linear resampling in time) to that duration,
   the mean over the regions' peak nodes, drawn from N(mean, std) with
   duration noise. A peak-to-peak segment lasts ``0.3 x`` the previous peak's
   duration ``+ 0.7 x`` the next one's (``peak_weights``).
3. *Region length normalisation.* Regions give paths of different lengths;
   every region is first resampled to the longest one, then the segment to the
   duration of step 2.
4. *Smoothing.* A Savitzky-Golay filter along time, then per segment and per
   landmark a sigmoid (eq. 1, shared timing for x and y, fitted by grid and
   exact amplitudes); ``sigmoid_weight = 1`` (default) replaces the motion by
   the sigmoid fit, smaller values blend it in.

**Coherent noise.** A share of the interior path nodes is replaced by random
nodes within ``noise_hops`` hops (undirected) that share a label with the
path's source or sink: the label(s) peaking in the end nodes (or, for a
neutral source, the sink's peak labels).

The regions are assembled into a (frames, 68, 2) displacement animation that
is added to a neutral face.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.csgraph import dijkstra
from scipy.special import expit

from ..io.ckplus import EMOTIONS, emotion_code
from .regiongraph import RegionGraph
from .preprocess import sigmoid_grid_fit

log = logging.getLogger("animsynth.facegraph.synthesis")


class SynthesisError(RuntimeError):
    """A label cannot be reached in a region graph (disconnected graph or unknown label)."""


@dataclass
class Animation:
    """A synthesised animation.

    Attributes
    ----------
    disp : ndarray (frames, 68, 2)   displacements from the neutral face
    segments : list of (start, stop, label)
    paths : dict region -> list (per segment) of node-id arrays (after noise)
    raw_paths : dict region -> list of Dijkstra paths (before noise)
    jumps : list of (segment, region, from node, to neutral node) restarts (see module docs)
    """

    disp: np.ndarray
    segments: list = field(default_factory=list)
    paths: dict = field(default_factory=dict)
    raw_paths: dict = field(default_factory=dict)
    jumps: list = field(default_factory=list)

    @property
    def n_frames(self) -> int:
        return int(self.disp.shape[0])

    def positions(self, neutral: np.ndarray) -> np.ndarray:
        """Landmark positions: ``neutral`` (68, 2) plus the displacements."""
        return np.asarray(neutral, float)[None] + self.disp


def resample(traj: np.ndarray, n: int) -> np.ndarray:
    """Linear resampling of a trajectory (T, ...) to ``n`` frames over the same time span."""
    T = traj.shape[0]
    if T == n:
        return traj.copy()
    if T == 1:
        return np.repeat(traj, n, axis=0)
    x = np.linspace(0.0, T - 1, n)
    i0 = np.minimum(np.floor(x).astype(int), T - 2)
    w = (x - i0).reshape((-1,) + (1,) * (traj.ndim - 1))
    return traj[i0] * (1.0 - w) + traj[i0 + 1] * w


def _path(pred: np.ndarray, src: int, dst: int) -> np.ndarray:
    out = [dst]
    while out[-1] != src:
        p = pred[out[-1]]
        if p < 0:
            raise SynthesisError("broken predecessor chain")
        out.append(int(p))
    return np.array(out[::-1], int)


def hop_neighbours(g: RegionGraph, node: int, hops: int) -> np.ndarray:
    """Nodes within ``hops`` undirected hops of ``node`` (excluding it)."""
    A = g.undirected()
    seen = {int(node)}
    frontier = [int(node)]
    for _ in range(int(hops)):
        nxt = []
        for u in frontier:
            for v in A.indices[A.indptr[u]:A.indptr[u + 1]]:
                v = int(v)
                if v not in seen:
                    seen.add(v)
                    nxt.append(v)
        frontier = nxt
        if not frontier:
            break
    seen.discard(int(node))
    return np.array(sorted(seen), int)


class FaceSynthesizer:
    """Label-driven synthesis on region graphs.

    Parameters
    ----------
    graphs : dict region -> RegionGraph
    savgol_window, savgol_order : int
        Savitzky-Golay smoothing (step 4); the window is shrunk to the
        animation length when needed (odd), smoothing is skipped below order + 2 frames.
    sigmoid_weight : float in [0, 1]
        Blend of the per-segment sigmoid fit into the smoothed motion (step 4); 1 = fully applied.
    noise_share : float in [0, 1]
        Share of interior path nodes replaced by coherent noise.
    noise_hops : int
        Neighbourhood radius (hops) of the replacement nodes.
    duration_noise : bool
        Draw the segment duration from N(mean, std) of the peak node instead of using the mean.
    peak_weights : (float, float)
        Duration of a peak-to-peak segment: weights of the previous and the next peak's duration.
    """

    def __init__(self, graphs: dict[str, RegionGraph], savgol_window: int = 7, savgol_order: int = 2,
                 sigmoid_weight: float = 1.0, noise_share: float = 0.0, noise_hops: int = 2,
                 duration_noise: bool = False, peak_weights=(0.3, 0.7)):
        if not 0.0 <= sigmoid_weight <= 1.0:
            raise ValueError("sigmoid_weight must be in [0, 1]")
        if not 0.0 <= noise_share <= 1.0:
            raise ValueError("noise_share must be in [0, 1]")
        if savgol_window < 3 or savgol_window % 2 == 0 or savgol_order >= savgol_window:
            raise ValueError("savgol_window must be odd, >= 3 and > savgol_order")
        self.graphs = graphs
        self.savgol_window = int(savgol_window)
        self.savgol_order = int(savgol_order)
        self.sigmoid_weight = float(sigmoid_weight)
        self.noise_share = float(noise_share)
        self.noise_hops = int(noise_hops)
        self.duration_noise = bool(duration_noise)
        pw = tuple(float(w) for w in peak_weights)
        if len(pw) != 2 or min(pw) < 0 or abs(sum(pw) - 1.0) > 1e-9:
            raise ValueError("peak_weights must be two non-negative weights summing to 1")
        self.peak_weights = pw

    # ------------------------------------------------------------------
    def start_nodes(self, sample: int | None = None) -> dict[str, int]:
        """Start node per region: the node of a sample's neutral pose, or (None)
        the neutral node shared by most samples."""
        out = {}
        for r, g in self.graphs.items():
            if sample is None:
                out[r] = int(np.bincount(g.start_of_sample).argmax())
            else:
                out[r] = int(g.start_of_sample[sample])
        return out

    def _neutral_reaching(self, g: RegionGraph, code: int):
        """The neutral node (most samples' start first) from which a peak of ``code`` is reachable."""
        cache = self.__dict__.setdefault("_neutral_cache", {})
        key = (g.name, id(g), code)
        if key not in cache:
            starts, counts = np.unique(g.start_of_sample, return_counts=True)
            peaks = g.peak_nodes(code)
            cache[key] = None
            for s in starts[np.argsort(-counts, kind="stable")]:
                d = dijkstra(g.csr(), directed=True, indices=int(s))
                if np.isfinite(d[peaks]).any():
                    cache[key] = int(s)
                    break
        return cache[key]

    def _coherent_noise(self, g: RegionGraph, path: np.ndarray, rng) -> np.ndarray:
        path = path.copy()
        interior = np.arange(1, len(path) - 1)
        k = int(round(self.noise_share * interior.size))
        if k == 0:
            return path
        labels = int(g.peak_mask[path[0]]) | int(g.peak_mask[path[-1]])
        if labels == 0:
            labels = int(g.label_mask[path[-1]])
        for i in np.sort(rng.choice(interior, size=k, replace=False)):
            u = path[i]
            nb = hop_neighbours(g, u, self.noise_hops)
            nb = nb[(g.label_mask[nb].astype(int) & labels) != 0]
            if nb.size:
                path[i] = nb[rng.integers(nb.size)]
        return path

    def _expand(self, g: RegionGraph, path: np.ndarray, first: bool) -> np.ndarray:
        """Step 1 for one region path -> (frames, Lf, 2), ending on the path's last node."""
        D = g.disp
        if len(path) == 1:
            return D[path][:1].copy()
        m = len(path)
        nxt = np.r_[path[1:], path[-1]]
        prv = np.r_[path[0], path[:-1]]
        ahead = D[nxt] - D[path]                                  # (m, Lf, 2)
        ahead[-1] = D[path[-1]] - D[path[-2]]                      # last node: keep the arrival direction
        length = np.sqrt((ahead ** 2).sum(-1))
        unit = np.where(length[..., None] > 0, ahead / np.where(length > 0, length, 1.0)[..., None], 0.0)
        half_next = 0.5 * np.sqrt(((D[nxt] - D[path]) ** 2).sum(-1))   # (m, Lf); 0 for the last node
        half_prev = 0.5 * np.sqrt(((D[path] - D[prv]) ** 2).sum(-1))   # 0 for the first node
        n = np.maximum(1, np.rint(g.merge_count[path]).astype(int))
        n[-1] = 1  # the path ends on the peak pose itself
        if not first:
            n[0] = 0  # the previous segment ended on this node
        ks = np.repeat(np.arange(m), n)
        js = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        off = (js - (n[ks] - 1) / 2.0)[:, None] * g.speed[path[ks]]      # (frames, Lf), centred on the node
        off = np.clip(off, -half_prev[ks], half_next[ks])
        return D[path[ks]] + off[..., None] * unit[ks]

    def _duration(self, g: RegionGraph, node: int, rng):
        mu, sd = g.peak_dur_mean[node], g.peak_dur_std[node]
        if not np.isfinite(mu):
            return np.nan, 0.0
        return float(mu), float(sd) if np.isfinite(sd) else 0.0

    def _smooth(self, disp: np.ndarray, segments: list) -> np.ndarray:
        T = disp.shape[0]
        w = min(self.savgol_window, T if T % 2 else T - 1)
        from scipy.signal import savgol_filter  # imported here: the jobs that synthesise nothing skip scipy.signal

        sm = savgol_filter(disp, w, self.savgol_order, axis=0, mode="interp") if w > self.savgol_order + 1 else disp
        if self.sigmoid_weight == 0.0:
            return sm
        out = sm.copy()
        for a, b, _ in segments:
            seg = sm[a:b]
            if b - a < 4:
                continue
            base = seg[0]
            A, Bm, k, c = sigmoid_grid_fit(seg - base)
            t = np.arange(b - a, dtype=float)
            fit = base + A[None] + Bm[None] * expit(k[None, :] * (t[:, None] - c[None, :]))[..., None]
            out[a:b] = (1.0 - self.sigmoid_weight) * seg + self.sigmoid_weight * fit
        return out

    # ------------------------------------------------------------------
    def synthesize(self, labels, start: dict | None = None, rng=None, peak_rng=None,
                   peak_nodes: dict | None = None) -> Animation:
        """Animation through the peaks of ``labels`` (names or CK+ codes), in order.

        Parameters
        ----------
        labels : sequence of str or int
        start : dict region -> node, optional (default: :meth:`start_nodes`)
        rng : numpy Generator or int seed (peak choice and noise)
        peak_rng : numpy Generator or int seed, optional
            Separate generator for the peak-node choice (then ``rng`` drives only the noise).
        peak_nodes : dict region -> node, optional
            Peak node of the first label per region instead of a random one
            (re-synthesis of a database sample: its own peak nodes).
        """
        rng = np.random.default_rng(rng)
        peak_rng = rng if peak_rng is None else np.random.default_rng(peak_rng)
        codes = [emotion_code(lab) for lab in labels]
        if not codes:
            raise ValueError("need at least one expression label")
        cur = dict(start) if start is not None else self.start_nodes()
        segments, parts = [], []
        paths = {r: [] for r in self.graphs}
        raw = {r: [] for r in self.graphs}
        jumps = []
        t0 = 0
        prev_dur = None
        for si, code in enumerate(codes):
            trajs, durs = {}, []
            for r, g in self.graphs.items():
                target, pred = self._peak_target(r, g, code, si, cur, peak_nodes, peak_rng, jumps)
                p = _path(pred, cur[r], target)
                raw[r].append(p)
                if self.noise_share > 0:
                    p = self._coherent_noise(g, p, rng)
                paths[r].append(p)
                trajs[r] = self._expand(g, p, si == 0)
                durs.append(self._duration(g, target, rng))
                cur[r] = target
            # step 3: every region to the longest region path
            longest = max(len(t) for t in trajs.values())
            n, prev_dur = self._segment_frames(durs, si, prev_dur, longest, rng)
            seg = np.zeros((n, 68, 2))
            for r, g in self.graphs.items():
                seg[:, g.landmarks] = resample(resample(trajs[r], longest), n)
            parts.append(seg)
            segments.append((t0, t0 + n, EMOTIONS[code]))
            t0 += n
        disp = self._smooth(np.concatenate(parts, axis=0), segments)
        return Animation(disp, segments, paths, raw, jumps)

    def _peak_target(self, r, g, code: int, si: int, cur: dict, peak_nodes, peak_rng, jumps: list):
        """``(peak node, shortest-path predecessors from cur[r])`` of region ``r`` for label ``code`` (the
        ``si``-th): a random peak node reachable from ``cur[r]`` (or the given ``peak_nodes`` for the first label),
        restarting from a neutral node (logged in ``jumps``, ``cur[r]`` moved) when none is reachable."""
        peaks = g.peak_nodes(code)
        if peaks.size == 0:
            raise SynthesisError(f"region {r!r}: no peak node for label {EMOTIONS[code]!r} "
                                 "(no database sample has that label)")
        dist, pred = dijkstra(g.csr(), directed=True, indices=cur[r], return_predecessors=True)
        reach = peaks[np.isfinite(dist[peaks])]
        if reach.size == 0:
            alt = self._neutral_reaching(g, code)
            if alt is None:
                raise SynthesisError(f"region {r!r}: no {EMOTIONS[code]!r} peak node is reachable from "
                                     f"node {cur[r]} nor from any neutral node (graph not connected)")
            log.warning("region %s: no %s peak reachable from node %d; restarting from neutral node %d",
                        r, EMOTIONS[code], cur[r], alt)
            jumps.append((si, r, int(cur[r]), alt))
            cur[r] = alt
            dist, pred = dijkstra(g.csr(), directed=True, indices=cur[r], return_predecessors=True)
            reach = peaks[np.isfinite(dist[peaks])]
        if peak_nodes is not None and si == 0:
            target = int(peak_nodes[r])
            if target not in set(reach.tolist()):
                raise SynthesisError(f"region {r!r}: requested peak node {target} is not a reachable "
                                     f"{EMOTIONS[code]!r} peak node")
            return target, pred
        return int(reach[peak_rng.integers(reach.size)]), pred

    def _segment_frames(self, durs: list, si: int, prev_dur, longest: int, rng) -> tuple[int, float | None]:
        """``(frames, duration)`` of the ``si``-th segment (step 2): the peak nodes' mean neutral-to-peak duration
        (drawn with its spread when ``duration_noise``, blended with the previous segment's by ``peak_weights``),
        or the longest region path when no node knows a duration."""
        mus = np.array([d[0] for d in durs])
        sds = np.array([d[1] for d in durs])
        if not np.isfinite(mus).any():
            return longest, prev_dur
        mu, sd = float(np.nanmean(mus)), float(np.nanmean(np.where(np.isfinite(mus), sds, np.nan)))
        d = rng.normal(mu, sd) if (self.duration_noise and sd > 0) else mu
        if si > 0 and prev_dur is not None:
            d = self.peak_weights[0] * prev_dur + self.peak_weights[1] * d
        return max(1, int(np.rint(d))), d
