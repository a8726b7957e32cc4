"""The fast paths of graph creation give exactly the graphs of the reference run.

``tests/facegraph_reference.json`` holds a SHA-256 digest (with dtype and
shape) of every fitted array (per-sample thresholds, node data, edges,
weights, search tables) of four configurations on a small synthetic database,
computed with the implementation before the merge loop and the nearest-node
start search were optimised. Any change of a single bit in a threshold or a
node fails here; regenerate the file (``python tests/test_facegraph_reference.py``)
only for a deliberate change of results, and say so in the commit.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from animsynth.facegraph import FacePreprocessor, FaceGraphModel
from animsynth.facegraph.model import _nn_similarity
from animsynth.facegraph.samplegraphs import PoseStack, create_sample_graphs, region_data, sample_nodes
from animsynth.synth.faces import generate_sequences

REFERENCE = Path(__file__).parent / "facegraph_reference.json"
DB_KWARGS = dict(n_subjects=3, n_sequences=8, total_frames=200, n_unlabelled=0, seed=5)
CONFIGS = [
    dict(creation_compression=50, merge_compression=50, seed=7),
    dict(creation_compression=20, merge_compression=70, creation_tolerance=10, merge_tolerance=20, seed=0),
    dict(creation_compression=50, merge_compression=50, seed=7, thresholds="global"),
    dict(creation_compression=30, merge_compression=40, seed=1, procrustes=False),
]
GRAPH_FIELDS = ("disp", "speed", "merge_count", "pose_count", "visits", "label_mask", "peak_mask", "peak_dur_mean",
                "peak_dur_std", "peak_dur_n", "edges", "weights", "start_of_sample", "peak_of_sample")


def fitted_arrays(model: FaceGraphModel, prefix: str) -> dict:
    out = {}
    for r, g in model.graphs_.items():
        for k in GRAPH_FIELDS:
            out[f"{prefix}/{r}/{k}"] = np.asarray(getattr(g, k))
        out[f"{prefix}/{r}/creation_thresholds"] = model.creation_thresholds_[r]
        out[f"{prefix}/{r}/merge_thresholds"] = model.merge_thresholds_[r]
    out[f"{prefix}/search"] = model.search_.select_dtypes("number").to_numpy(float)
    out[f"{prefix}/samples"] = model.samples_.select_dtypes("number").to_numpy(float)
    return out


def digest(a: np.ndarray) -> str:
    a = np.ascontiguousarray(a)
    return f"{a.dtype.str}{list(a.shape)}:" + hashlib.sha256(a.tobytes()).hexdigest()


def reference_digests() -> dict:
    db = FacePreprocessor().fit_transform(generate_sequences(**DB_KWARGS), source="reference")
    out = {}
    for i, c in enumerate(CONFIGS):
        out.update({k: digest(v) for k, v in fitted_arrays(FaceGraphModel(**c).fit(db), f"c{i}").items()})
    return out


@pytest.fixture(scope="module")
def small_db():
    return FacePreprocessor().fit_transform(generate_sequences(**DB_KWARGS), source="reference")


@pytest.mark.parametrize("i", range(len(CONFIGS)))
def test_graphs_identical_to_reference(small_db, i):
    ref = json.loads(REFERENCE.read_text())
    prefix = f"c{i}"
    got = {k: digest(v) for k, v in fitted_arrays(FaceGraphModel(**CONFIGS[i]).fit(small_db), prefix).items()}
    keys = [k for k in ref if k.startswith(prefix + "/")]
    assert len(keys) > 20 and sorted(keys) == sorted(got), "fitted outputs changed name"
    differ = [k for k in keys if ref[k] != got[k]]
    assert not differ, f"outputs differ from the reference run: {differ[:8]}"


def _nn_similarity_unpruned(nodes, red, rng, k=256, chunk=32):
    """The plain all-pairs form the pruned search must reproduce bit for bit."""
    q = rng.choice(nodes.n, size=min(k, nodes.n), replace=False)
    D = nodes.disp[:, red]
    out = []
    for a in range(0, len(q), chunk):
        qq = q[a:a + chunk]
        d = np.sqrt(((D[None] - D[qq][:, None]) ** 2).sum(-1)).sum(-1)
        d[nodes.sample[None, :] == nodes.sample[qq][:, None]] = np.inf
        out.append(d.min(1))
    out = np.concatenate(out) if out else np.zeros(0)
    return out[np.isfinite(out)]


@pytest.mark.parametrize("threshold", [0.3, 2.0, 10.0])
def test_pruned_nearest_node_search_is_exact(small_db, threshold):
    rd = region_data(small_db)
    stack = PoseStack.from_region_data(rd)
    assign = create_sample_graphs(stack, np.full(len(rd), threshold))[0]
    for i, r in enumerate(rd):
        nd = sample_nodes(rd[r], assign[i])
        want = _nn_similarity_unpruned(nd, rd[r].red, np.random.default_rng(4))
        got = _nn_similarity(nd, rd[r].red, np.random.default_rng(4))
        assert want.size > 0
        np.testing.assert_array_equal(got, want)


if __name__ == "__main__":  # regenerate the reference (deliberate changes of results only)
    REFERENCE.write_text(json.dumps(reference_digests(), indent=0, sort_keys=True) + "\n")
    print(f"wrote {REFERENCE}", file=sys.stderr)
