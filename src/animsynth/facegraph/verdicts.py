"""The claims of Serra et al. 2018 (and of the face-graph comparison) decided from the facegraph tables.

Rows are built with :func:`animsynth.verdicts.row` (which refuses a word outside the common vocabulary)
and returned as the common verdict table (:func:`animsynth.verdicts.table`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from ..verdicts import fmt, row, table


def _rank_trend(x, y, samples: dict | None, order: list[str], n_boot: int = 200, seed: int = 0):
    """Spearman rho of y over x (configurations) and the share of bootstrap
    resamples of the database samples (same resample in every configuration)
    in which rho stays > 0."""
    rho, p = spearmanr(x, y)
    share = np.nan
    if samples and all(n in samples for n in order):
        M = np.stack([samples[n]["landmark_diff_px"].to_numpy(float) for n in order])  # (configs, S)
        rng = np.random.default_rng(seed)
        pos = 0
        for _ in range(n_boot):
            idx = rng.integers(M.shape[1], size=M.shape[1])
            r, _ = spearmanr(x, np.nanmean(M[:, idx], 1))
            pos += bool(r > 0)
        share = pos / n_boot
    return float(rho), float(p), share


def build_verdicts(table1: pd.DataFrame, baseline: pd.DataFrame, uniqueness: pd.DataFrame, source: str,
             samples: dict | None = None) -> pd.DataFrame:
    """The paper's claims checked against our deterministic tables.

    Parameters
    ----------
    table1, baseline, uniqueness : DataFrame
        ``table1.csv`` (one row per configuration), ``baseline.csv`` and ``uniqueness.csv`` as written
        by :mod:`.jobs`.
    source : str
        What the data are (the database's source), for the ``data`` column.
    samples : dict, optional
        Configuration name -> per-sample table (for the bootstrap of the trend verdict).

    Returns
    -------
    DataFrame
        The common verdict table (:data:`animsynth.verdicts.COLUMNS`), one row per claim; every verdict
        word is checked against :data:`animsynth.verdicts.VOCABULARY`.
    """
    rows = []
    t = table1
    data = f"{'synthetic CK+-layout' if source.startswith('synthetic') else source}, {len(t)} configurations"

    def add(claim, paper_value, ours, verdict, evidence, src):
        rows.append(row(claim, verdict, evidence, paper_value=paper_value, ours=ours, data=data, source=src))

    cb = t["creation_in_band_pct"].astype(float)
    mb = t["merge_in_band_pct"].astype(float)
    ok = (cb >= 95) & (mb >= 95)
    add("Thresholds optimised per sample reach the target compression band",
        "targets with tolerances, e.g. creation 0.2 +/- 0.1, merge 0.7 +/- 0.3",
        f"samples in band: creation {fmt(cb.min())}-{fmt(cb.max())} %, merge {fmt(mb.min())}-{fmt(mb.max())} %",
        "reproduced" if ok.all() else ("partly" if ok.any() else "not reproduced"),
        f"{int(ok.sum())}/{len(t)} configurations have >= 95 % of the samples of every region inside both bands "
        "(step-halving search per sample; a sample whose compression jumps over a narrow band cannot hit it).",
        "facegraph/thresholds.csv")
    dd = t["duration_diff"].astype(float)
    pd_ = t["paper_duration_diff"].astype(float)
    rd = t["random_duration_diff"].astype(float)
    near = dd <= 0.25  # the paper's largest mean difference is 0.11 frames
    verdict = "reproduced" if near.all() else ("partly" if near.any() else "not reproduced")
    add("Synthesised sequences keep the original durations (duration difference near 0)",
        f"{fmt(pd_.min())}-{fmt(pd_.max())} frames" if pd_.notna().any() else "",
        f"{fmt(dd.min())}-{fmt(dd.max())} frames", verdict,
        f"{int(near.sum())}/{len(t)} configurations within 0.25 frames. "
        f"Counterpart re-synthesis (own neutral and peak node) stretched to the peak nodes' stored duration: "
        f"mean |difference| {fmt(dd.min())}-{fmt(dd.max())} frames (sd up to {fmt(t.duration_diff_sd.max())}); "
        f"a peak node that merged several samples' peaks stores their mean ({fmt(t.shared_peak_pct.min())}-"
        f"{fmt(t.shared_peak_pct.max())} % of sample-region peaks are shared, rising with compression). "
        f"A random same-label peak gives {fmt(rd.min())}-{fmt(rd.max())} frames.", "facegraph/table1.csv")
    lm = t["landmark_diff_px"].astype(float)
    inside = (lm >= 1.4) & (lm <= 2.5)
    pl = t["paper_landmark_diff_px"].astype(float)
    add("Landmark difference of re-synthesised sequences lies in the paper's 1.4-2.5 px band",
        f"{fmt(pl.min())}-{fmt(pl.max())} px" if pl.notna().any() else "1.4-2.5 px",
        f"{fmt(lm.min())}-{fmt(lm.max())} px",
        "reproduced" if inside.all() else ("partly" if inside.any() else "not reproduced"),
        f"{int(inside.sum())}/{len(t)} configurations inside 1.4-2.5 px; ours "
        f"{'below' if lm.max() < 1.4 else 'above' if lm.min() > 2.5 else 'around'} the band on these data "
        f"(linear neutral-to-peak interpolation: {fmt(t.linear_landmark_diff_px.min())}-"
        f"{fmt(t.linear_landmark_diff_px.max())} px).", "facegraph/table1.csv")
    order = t["config"].tolist()
    rho, p, share = (_rank_trend(t["node_compression_pct"].astype(float), lm, samples, order)
                     if len(t) > 2 else (np.nan, np.nan, np.nan))
    prho = np.nan
    if pl.notna().sum() > 2:
        prho = float(spearmanr(t["paper_node_compression_pct"].astype(float), pl)[0])
    if not np.isfinite(rho):
        verdict = "not reproduced"
    elif rho > 0 and p < 0.05 and (np.isnan(share) or share >= 0.95):
        verdict = "reproduced"
    elif rho > 0:
        verdict = "within noise"
    else:
        verdict = "contradicted" if p < 0.05 else "not reproduced"
    add("Landmark error rises with compression",
        f"Spearman rho {fmt(prho)} over the published rows" if np.isfinite(prho) else "",
        f"Spearman rho {fmt(rho)} (p={fmt(p)})", verdict,
        f"Rank correlation of landmark difference with node compression over {len(t)} configurations; "
        f"rho > 0 in {fmt(100 * share) if np.isfinite(share) else 'n/a'} % of 200 bootstrap resamples of the "
        "database samples.", "facegraph/table1.csv")
    nc = t["node_compression_pct"].astype(float)
    pn = t["paper_node_compression_pct"].astype(float)
    if pn.notna().any():
        diff = (nc - pn).abs()
        add("Node compression for the published targets (may be negative: more nodes than poses)",
            f"{fmt(pn.min())} to {fmt(pn.max())} %", f"{fmt(nc.min())} to {fmt(nc.max())} %",
            "reproduced" if (diff <= 10).all() else ("partly" if (diff <= 10).any() else "not reproduced"),
            f"|ours - paper| <= 10 points in {int((diff <= 10).sum())}/{len(t)} configurations (median "
            f"{fmt(diff.median())} points). With node compression = 1 - nodes / poses and stage compressions "
            "1 - nodes / poses (creation) and 1 - final / sample nodes (merge), five region graphs hold at least "
            "5 (1 - c_max)(1 - m_max) nodes per pose (c_max, m_max: upper band ends), e.g. >= 2.4 poses for "
            "0.1 +/- 0.1, 0.2 +/- 0.2, where the paper prints -54 % (1.54); its stage compressions must be measured "
            "differently, which the text does not let us determine. Where in a wide band a sample lands depends on "
            "the search start.", "facegraph/table1.csv")
    region = baseline[baseline.method.str.startswith("region graphs")].iloc[0]
    face = baseline[baseline.method.str.startswith("face graph")]
    smaller = face.memory_mb > region.memory_mb
    add("Region graphs need less memory than the face graph (Zhang et al. 2004)", "",
        f"{fmt(region.memory_mb)} MB vs {fmt(face.memory_mb.min())}-{fmt(face.memory_mb.max())} MB",
        "reproduced" if smaller.all() else ("partly" if smaller.any() else "not reproduced"),
        "float32 storage of what synthesis needs; complete face graphs hold N^2 weights"
        + ("" if face.built.all() else " (graphs too large to build: memory computed from their size)") + ".",
        "facegraph/baseline.csv")
    work_region = float(region.edges + region.nodes * np.log2(max(region.nodes, 2)))
    work_face = (face.edges + face.nodes * np.log2(face.nodes.clip(lower=2))).astype(float)
    add("Path finding on region graphs is faster than on the face graph", "face graph ~1.9 s per path",
        f"Dijkstra work (E + N log N) {fmt(work_region)} vs {fmt(work_face.min())}-{fmt(work_face.max())}",
        "reproduced" if (work_face > 10 * work_region).all() else "partly",
        "Compared on graph size (deterministic); measured path times are in facegraph/baseline_timing.csv.",
        "facegraph/baseline.csv")
    built = face[face.built]
    if len(built):
        better = built.landmark_diff_px > region.landmark_diff_px
        add("Region graphs reproduce database sequences more accurately than the face graph", "",
            f"region graphs {fmt(region.landmark_diff_px)} px vs face graph {fmt(built.landmark_diff_px.min())}-"
            f"{fmt(built.landmark_diff_px.max())} px",
            "reproduced" if better.all() else ("partly" if better.any() else "contradicted"),
            "Same queries (neutral to own peak); the face graph's shortest path on the database poses can follow "
            "the sample itself, so it is a strong baseline for re-synthesis.", "facegraph/baseline.csv")
    lin = t["linear_landmark_diff_px"].astype(float)
    add("The graph adds over straight neutral-to-peak interpolation (landmark difference)", "",
        f"graph {fmt(lm.median())} px vs linear {fmt(lin.median())} px (medians)",
        "reproduced" if (lm < lin).all() else ("partly" if (lm < lin).any() else "not reproduced"),
        f"Graph counterpart below the linear baseline in {int((lm < lin).sum())}/{len(t)} configurations; "
        f"velocity angle {fmt(t.velocity_angle_diff_pct.median())} % vs {fmt(t.linear_velocity_angle_diff_pct.median())} %. "
        "The reference is the pre-processed sequence, whose eq.-1 fit (one timing for x and y) moves every landmark "
        "on a straight line, so straight interpolation to the true peak pose has no direction error by construction; "
        "it also knows the peak pose, which the graph must find.",
        "facegraph/table1.csv")
    u = uniqueness.reset_index(drop=True)
    plain, noisy, full = u.iloc[0], u.iloc[2], u.iloc[3]
    add("Coherent (node and duration) noise makes repeated runs of one label sequence distinct", "",
        f"{int(noisy.distinct)}/{int(noisy.runs)} distinct",
        "reproduced" if noisy.distinct == noisy.runs and noisy.distinct > plain.distinct else
        ("partly" if noisy.distinct > plain.distinct else "not reproduced"),
        f"{plain.labels}, same peak nodes: {int(plain.distinct)}/{int(plain.runs)} distinct without noise, "
        f"{int(noisy.distinct)}/{int(noisy.runs)} with node + duration noise (mean pairwise distance "
        f"{fmt(noisy.distance_mean_px)} px); random peaks too: {int(full.distinct)}/{int(full.runs)}.",
        "facegraph/uniqueness.csv")
    return table(rows)
