"""The region motion graph container (node data, edges) and its storage.

**Node data.** Mean displacement of all region landmarks, CK+ label mask of
the samples passing through, peak-label mask (labels whose peak pose is in the
node), mean consecutive-merge count (mean run length of the visits), mean
landmark speed, and for peak nodes the mean and std of the neutral-to-peak
duration (frames) of the samples peaking there (motion recovery step 2). Most
peak nodes hold the peak of a single sample and so have no spread of their
own; for them the stored std is that of the durations of the same label in
the region (0 if that label has a single sample), so duration noise stays
possible.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix

from ..atomic import atomic_path

#: Added to every edge weight so that ``scipy.sparse.csgraph`` keeps zero-similarity edges.
EDGE_EPS = 1e-9


@dataclass
class RegionGraph:
    """A region motion graph (see module docs for the node data)."""

    name: str
    landmarks: np.ndarray        # (Lf,) landmark ids
    red: np.ndarray              # (Lr,) reduced positions in ``landmarks``
    disp: np.ndarray             # (N, Lf, 2) mean displacement
    speed: np.ndarray            # (N, Lf) mean landmark speed (px/frame)
    merge_count: np.ndarray      # (N,) mean consecutive-merge count (poses per visit)
    pose_count: np.ndarray       # (N,) poses absorbed
    visits: np.ndarray           # (N,) sample nodes absorbed
    label_mask: np.ndarray       # (N,) uint8 bit e = a sample of emotion e passes through
    peak_mask: np.ndarray        # (N,) uint8 bit e = a sample of emotion e peaks here
    peak_dur_mean: np.ndarray    # (N,) NaN for non-peak nodes
    peak_dur_std: np.ndarray     # (N,) (label-pooled for single-peak nodes, see module docs)
    peak_dur_n: np.ndarray       # (N,) peak durations observed in the node
    edges: np.ndarray            # (E, 2) int
    weights: np.ndarray          # (E,)
    start_of_sample: np.ndarray  # (S,) node holding each sample's first (neutral) pose
    peak_of_sample: np.ndarray   # (S,) node holding each sample's peak pose
    info: dict = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        return int(self.disp.shape[0])

    @property
    def n_edges(self) -> int:
        return int(self.edges.shape[0])

    def csr(self) -> csr_matrix:
        if getattr(self, "_csr", None) is None:
            n = self.n_nodes
            self._csr = csr_matrix((self.weights, (self.edges[:, 0], self.edges[:, 1])), shape=(n, n))
        return self._csr

    def undirected(self) -> csr_matrix:
        if getattr(self, "_und", None) is None:
            a = self.csr()
            self._und = ((a + a.T) > 0).astype(np.int8).tocsr()
        return self._und

    def peak_nodes(self, emotion: int) -> np.ndarray:
        return np.flatnonzero(self.peak_mask & np.uint8(1 << int(emotion)))

    def nbytes(self) -> int:
        """Bytes of what synthesis needs, as float32/int32: per node the mean
        displacement (Lf x 2), mean speed (Lf), merge count, peak mean/std and
        the two label masks (counted as 4 bytes each); per edge two ids and a weight."""
        lf = len(self.landmarks)
        return 4 * (self.n_nodes * (3 * lf + 5) + 3 * self.n_edges)

    # -- storage -----------------------------------------------------------
    _ARRAYS = ("landmarks", "red", "disp", "speed", "merge_count", "pose_count", "visits", "label_mask",
               "peak_mask", "peak_dur_mean", "peak_dur_std", "peak_dur_n", "edges", "weights", "start_of_sample",
               "peak_of_sample")

    def to_arrays(self, prefix: str) -> dict:
        d = {f"{prefix}{k}": getattr(self, k) for k in self._ARRAYS}
        d[f"{prefix}info"] = np.array(repr(sorted(self.info.items())))
        return d

    @classmethod
    def from_arrays(cls, z, prefix: str, name: str) -> "RegionGraph":
        import ast

        kw = {k: np.array(z[f"{prefix}{k}"]) for k in cls._ARRAYS}
        info = dict(ast.literal_eval(str(z[f"{prefix}info"])))
        return cls(name=name, info=info, **kw)


def save_graphs(path, graphs: dict[str, RegionGraph], meta: dict | None = None) -> None:
    arrays = {}
    for r, g in graphs.items():
        arrays.update(g.to_arrays(f"{r}__"))
    arrays["regions"] = np.array(list(graphs))
    arrays["meta"] = np.array(repr(sorted((meta or {}).items())))
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, **arrays)


def load_graphs(path) -> tuple[dict[str, RegionGraph], dict]:
    import ast

    with np.load(path, allow_pickle=False) as z:
        regions = [str(r) for r in z["regions"]]
        graphs = {r: RegionGraph.from_arrays(z, f"{r}__", r) for r in regions}
        meta = dict(ast.literal_eval(str(z["meta"])))
    return graphs, meta
