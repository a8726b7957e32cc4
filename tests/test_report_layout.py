"""The report at a glance: the scoreboard (counts equal claims.csv's, real and synthetic apart, sanity checks
apart), the summary read top-down (banner, provenance once, scoreboard, one short line per claim, a section per
family, the detailed tables), nothing of a long evidence text lost, and the report's home page opening on the
scoreboard."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from animsynth.families import get, report_order
from animsynth.report import (
    FAMILY_SECTION,
    LINE_LIMIT,
    build_summary,
    claim_anchor,
    claims_rst,
    claims_table,
    shorten,
    verdict_counts_md,
)
from animsynth.scoreboard import draw_scoreboard, sanity_checks, scoreboard_counts, scoreboard_figure
from animsynth.verdicts import VOCABULARY

WORDS = list(VOCABULARY)
LONG_EVIDENCE = ("Wilcoxon signed-rank over 4 subject groups: p = 0.031 (w1), 0.44 (w2), 0.12 (r1), 0.0078 (r2); "
                 "Holm-corrected across the family's 9 claims: 0.25, 1, 0.84, 0.07; bootstrap 95 % CI of the median "
                 "per-fold difference [-0.012, 0.004]; minimum effect 0.01 of the latent diagonal; holds on 3 of 5 "
                 "seeds and 7 of 12 folds, flips on seeds 2 and 4; groups: 4 subjects; ") * 3
LONG_OURS = ("median Error A 0.0512 (IQR 0.031-0.077) Delaunay vs 0.0498 (IQR 0.029-0.081) k-NN over 12 folds x "
             "5 seeds; Error F 0.113 vs 0.121; share of starts with Delaunay lower: A 0.42, F 0.58, per subset: "
             "w1 0.5 / 0.6, w2 0.3 / 0.4, r1 0.45 / 0.7, r2 0.4 / 0.6")
LONG_CLAIM = ("Delaunay-based motion graphs give lower Error A and Error F than k-NN graphs on every subset of the "
              "CMU walking and running trials, for leave-one-out held-out clips, at the paper's default parameters "
              "and with the vector field's 1/D^2 weighting")


def _verdicts(root, family, rows):
    p = root / family / "verdicts.csv"
    p.parent.mkdir(parents=True, exist_ok=True)
    full = [{"claim": "", "paper_value": "", "ours": "", "data": "", "verdict": "reproduced", "evidence": "",
             "source": "", **r} for r in rows]
    pd.DataFrame(full).to_csv(p, index=False)
    return p


def _run(tmp_path):
    """Verdict files of four families: real mocap (simplicial, resequencing, compare), synthetic faces."""
    simp = _verdicts(tmp_path, "simplicial", [
        {"claim": LONG_CLAIM, "paper_value": "0.068 vs 0.079", "ours": LONG_OURS, "verdict": "within noise",
         "evidence": LONG_EVIDENCE, "source": "simplicial/table2.csv"},
        {"claim": "Delaunay graph connected", "verdict": "reproduced", "evidence": "all folds",
         "source": "simplicial/folds.csv"},
        {"claim": "Error F below 0.1", "paper_value": "0.08", "ours": "0.12", "verdict": "not reproduced",
         "evidence": "12 of 12 folds above", "source": "simplicial/table2.csv"}])
    reseq = _verdicts(tmp_path, "resequencing", [
        {"claim": "ST-Isomap needs a smaller k", "paper_value": "k=4 vs 12", "ours": "k=5 vs 9", "verdict": "partly",
         "evidence": "walk yes, dance no", "source": "resequencing/table2_min_k.csv"},
        {"claim": "Lee metric lowers residual variance", "verdict": "contradicted", "evidence": "every dataset"}])
    face = _verdicts(tmp_path, "facegraph", [
        {"claim": "duration difference near 0", "paper_value": "0-0.11", "ours": "0.02", "verdict": "reproduced",
         "evidence": "15 configurations", "source": "facegraph/table1.csv"}])
    comp = _verdicts(tmp_path, "compare", [
        {"claim": "our graph skates less than fairmotion", "verdict": "reproduced", "evidence": "30 pairs"},
        {"claim": "replay copies the capture", "verdict": "reproduced", "evidence": "by construction"}])
    # the registry's families by their kind of data: the mocap ones on CMU, the faces synthetic, the mesh one skipped
    ran = [f for f in report_order() if f.data != "mesh"]
    skipped = [f for f in report_order() if f.data == "mesh"]
    real = {**{f.name: f.data == "mocap" for f in ran}, "data": True}
    data = {f.name: {"mocap": "CMU mocap", "faces": "synthetic CK+-layout database"}[f.data] for f in ran}
    prov = pd.DataFrame([{"family": f, "data": d, "status": "ran"} for f, d in data.items()]
                        + [{"family": f.name, "data": "mesh sequence samba", "status": "skipped: absent"}
                           for f in skipped])
    return [simp, reseq, face, comp], real, data, prov


def test_claims_get_ids_per_family_that_survive_the_real_first_order(tmp_path):
    paths, real, data, _ = _run(tmp_path)
    claims = claims_table(paths, data, real)
    assert list(claims.columns[:3]) == ["id", "paper", "family"]
    assert list(claims["id"]) == ["S1", "S2", "S3", "R1", "R2", "C1", "C2", "F1"]  # real data first
    assert claim_anchor("S12") == "claim-s12"


def _claims(n_per_family=(7, 5, 4, 3), sanity_in_compare=0, seed=0):
    rng = np.random.default_rng(seed)
    rows = []
    for (fam, real), n in zip((("simplicial", True), ("resequencing", True), ("facegraph", False), ("compare", True)),
                              n_per_family):
        letter = get(fam).letter
        for i in range(n):
            rows.append({"id": f"{letter}{i + 1}", "paper": fam.title(), "family": fam, "claim": f"c{i}",
                         "verdict": WORDS[rng.integers(len(WORDS))], "real": real,
                         "kind": "sanity check" if fam == "compare" and i >= n - sanity_in_compare else "finding"})
    return pd.DataFrame(rows)


@pytest.mark.parametrize("sanity", [0, 2])
def test_scoreboard_counts_equal_the_claims_and_every_claim_is_one_cell(tmp_path, sanity):
    claims = _claims(sanity_in_compare=sanity)
    fig, counts = draw_scoreboard(claims)
    try:
        # the counts drawn are claims.csv's, row by row and verdict by verdict; sanity checks apart
        is_sanity = sanity_checks(claims)
        assert int(is_sanity.sum()) == sanity
        for _, row in counts.iterrows():
            part = claims[(claims["family"] == row["family"]) & ~is_sanity]
            assert row["claims"] == len(part)
            for w in WORDS:
                assert row[w] == int((part["verdict"] == w).sum()), (row["family"], w)
            assert row["sanity_checks"] == int(is_sanity[claims["family"] == row["family"]].sum())
        assert int(counts["claims"].sum()) + int(counts["sanity_checks"].sum()) == len(claims)
        # the report's order (papers, then compare), of the families that have claims
        assert list(counts["family"]) == [f.name for f in report_order() if f.name in set(claims["family"])]
        ax = fig.axes[0]
        texts = [t.get_text() for t in ax.texts]
        for _, row in counts.iterrows():  # each row's counts are written under it
            line = next(t for t in texts if t.startswith(f"{row['claims']} claim"))
            for w in WORDS:
                if row[w]:
                    assert f"{row[w]} {w}" in line
        # one cell per claim, labelled with its id; synthetic cells hatched, real ones plain
        cells = {p.get_gid()[5:]: p for p in ax.patches if (p.get_gid() or "").startswith("cell:")}
        assert sorted(cells) == sorted(claims["id"])
        for _, r in claims.iterrows():
            assert bool(cells[r["id"]].get_hatch()) == (not r["real"]), r["id"]
        # sanity checks stand right of every finding
        if sanity:
            right = min(cells[i].get_x() for i in claims.loc[is_sanity, "id"])
            assert all(cells[i].get_x() < right for i in claims.loc[~is_sanity, "id"])
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert "real data" in legend and "synthetic data" in legend
        for w in WORDS:
            assert f"{w} ({int(counts[w].sum())})" in legend
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_scoreboard_png_is_written_and_a_foreign_verdict_word_is_kept(tmp_path):
    claims = _claims().drop(columns="kind")
    claims.loc[0, "verdict"] = "sanity check"  # a verdict word marking a sanity check
    claims.loc[1, "verdict"] = "inconclusive"  # a word outside the vocabulary: counted, drawn grey, never dropped
    png = tmp_path / "scoreboard.png"
    counts = scoreboard_figure(claims, png)
    with Image.open(png) as im:
        assert im.width > 600 and im.height > 300
    assert "inconclusive" in counts.columns
    simp = counts.set_index("family").loc["simplicial"]
    assert simp["inconclusive"] == 1 and simp["sanity_checks"] == 1 and simp["claims"] == 6
    assert counts.set_index("family").loc["facegraph", "data"] == "synthetic data"
    # a boolean marker column works too; without any marker, nothing is a sanity check
    assert sanity_checks(claims.assign(sanity_check=[False, False, True] + [False] * (len(claims) - 3))).sum() == 2
    assert not sanity_checks(_claims().drop(columns="kind")).any()
    assert scoreboard_counts(_claims().drop(columns="kind"))["sanity_checks"].sum() == 0


def test_shorten_cuts_at_a_word():
    assert shorten("a  b\nc", 10) == "a b c"
    s = shorten(LONG_CLAIM, 60)
    assert len(s) <= 60 and s.endswith("…") and LONG_CLAIM.startswith(s[:-1])


TIMING = [f"results/paper/meshdetail/{seq}/{name}_timing.csv" for seq in ("samba", "crane")
          for name in ("dembones", "gplvm", "multires")] + ["results/paper/compare/timing.csv"]
SOURCE_NOTE = ("Every number below is computed by the workflow on the data named above; paper values are quoted "
               "beside ours where the paper gives them.")


def _summary(tmp_path, demo=False, sanity=False):
    paths, real, data, prov = _run(tmp_path)
    if sanity:  # compare's claims true by construction, as compare/sanity_checks.csv gives them
        check = tmp_path / "compare" / "sanity_checks.csv"
        pd.DataFrame([{"claim": f"check {i}", "paper_value": "", "ours": "0", "data": "", "verdict": "reproduced",
                       "evidence": "by construction", "source": ""} for i in range(2)]).to_csv(check, index=False)
        paths = paths + [check]
    key = tmp_path / "table2.csv"
    pd.DataFrame({"subset": ["w1"], "error_a": [0.05]}).to_csv(key, index=False)
    other = tmp_path / "datasets.csv"
    pd.DataFrame({"subset": ["w1"], "frames": [300]}).to_csv(other, index=False)
    sections = [{"title": "Table I: datasets", "csv": str(other), "family": "data", "key": False},
                {"title": "Table II: median errors", "csv": str(key), "family": "simplicial", "key": True}]
    figures = {"simplicial": [{"src": "simplicial/figures/fig6_paths_delaunay.png", "caption": "red near black"}],
               "compare": [{"src": "compare/metrics.png", "caption": "boxes apart"},
                           {"src": "compare/strips.png", "caption": "seams in red"}]}
    md = build_summary(sections, paths, SOURCE_NOTE, prov, data, real, demo,
                       scoreboard_png="scoreboard.png", family_figures=figures, timing_tables=TIMING)
    return md, claims_table(paths, data, real)


def _claims_table_lines(md: str) -> list[str]:
    body = md[md.index("## Claims of the four papers"):]
    body = body[: body.index("\n## ", 5)]
    return [ln for ln in body.splitlines() if ln.startswith("| [")]


def test_summary_reads_top_down_with_scoreboard_first_and_provenance_once(tmp_path):
    md, claims = _summary(tmp_path)
    lines = md.splitlines()
    assert lines[0] == "# animsynth: reproduction summary"
    assert lines[2].startswith("**On real data** at full size")  # the banner (a real-data run)
    order = ["## What each part ran on", "![Scoreboard", "## Claims of the four papers", "## Gauch & Peters",
             "## Isomap / ST-Isomap", "## Serra et al.", "## The generators side by side", "## Detailed tables",
             "### Table I: datasets"]
    where = [md.index(s) for s in order]
    assert where == sorted(where), dict(zip(order, where))
    # nothing but the banner and the provenance table before the scoreboard
    head = md[: md.index("## Scoreboard")]
    assert head.count("\n## ") == 1 and "![" not in head
    assert md.count("What each part ran on") == 1
    assert md.count("skipped: absent") == 1  # the provenance table once, no prose copy of it
    # the scoreboard's counts table says what claims.csv says
    sb = md[md.index("## Scoreboard"): md.index("## Claims of the four papers")]
    assert "| Gauch & Peters (simplicial complex) | real data | 3 | 1 | 0 | 1 | 1 | 0 |" in sb
    # each family's key figure beside its key table, before its claims in full
    simp = md[md.index("## Gauch & Peters"): md.index("## Isomap")]
    assert simp.index("![red near black](simplicial/figures/fig6_paths_delaunay.png)") \
        < simp.index("### Table II: median errors") < simp.index("### Every claim in full")
    side = md[md.index("## The generators side by side"): md.index("## Detailed tables")]
    assert "(compare/metrics.png)" in side and "(compare/strips.png)" in side


def test_claims_table_is_one_short_line_per_claim_and_nothing_is_lost(tmp_path):
    md, claims = _summary(tmp_path)
    rows = _claims_table_lines(md)
    assert len(rows) == len(claims)
    assert max(len(r) for r in rows) <= LINE_LIMIT
    assert any(len(" ".join(LONG_EVIDENCE.split())) > LINE_LIMIT for _ in [0])  # the test's evidence is long
    anchors = set(re.findall(r'<a id="([^"]+)"></a>', md))
    for _, c in claims.iterrows():
        line = next(r for r in rows if r.startswith(f"| [{c['id']}](#"))
        target = re.match(r"\| \[[^]]+\]\(#([^)]+)\)", line).group(1)
        assert target in anchors, c["id"]
        # the claim's full entry, below its anchor, holds every text of the claim uncut
        entry = md[md.index(f'<a id="{target}"></a>'):]
        entry = entry[: entry.find("<a id=", 10) if "<a id=" in entry[10:] else len(entry)]
        for col in ("claim", "paper_value", "ours", "evidence", "data"):
            text = " ".join(str(c[col]).split())
            assert text in entry, (c["id"], col)
        assert c["verdict"] in entry
    # the long texts were cut in the table, not in the entry
    assert LONG_EVIDENCE.split()[0] not in "".join(rows)
    assert "…" in next(r for r in rows if r.startswith("| [S1]"))


def test_paper_run_summary_starts_with_banner_provenance_and_scoreboard(tmp_path):
    md, _ = _summary(tmp_path, demo=False)
    first = [b for b in md.split("\n\n") if b.strip()][:5]
    assert first[0].startswith("# animsynth")
    assert first[1].startswith("**On real data**") and "facegraph" in first[1]
    assert first[2] == "## What each part ran on"
    assert first[3].startswith("| family | data | kind | status |")
    assert "demo" not in md.lower()
    assert md.index("![Scoreboard") < md.index("| [")


def test_home_page_opens_on_the_scoreboard_and_links_each_claim_to_its_full_text(tmp_path):
    from docutils.core import publish_parts
    from docutils.utils import Reporter

    paths, real, data, prov = _run(tmp_path)
    claims = claims_table(paths, data, real)
    png = tmp_path / "scoreboard.png"
    scoreboard_figure(claims, png)
    fig = tmp_path / "metrics.png"
    Image.new("RGB", (2000, 500), "white").save(fig)
    rst = claims_rst(claims, prov, ["results/scoreboard.png", "results/compare/metrics.png",
                                    "results/simplicial/table2.csv"],
                     banner="**On real data** at full size: simplicial.", scoreboard_png=png,
                     family_figures={"compare": [{"png": fig, "src": "compare/metrics.png", "caption": "boxes"}]},
                     family_data=data)
    targets = "\n".join(f".. _{n}: javascript:void(0)" for n in ("scoreboard.png", "metrics.png", "table2.csv"))
    html = publish_parts(rst + "\n" + targets + "\n", writer="html",
                         settings_overrides={"report_level": Reporter.WARNING_LEVEL,
                                             "halt_level": Reporter.WARNING_LEVEL})["html_body"]
    # the first picture is the scoreboard, embedded (self-contained), before any table or list
    imgs = re.findall(r'<img [^>]*src="([^"]+)"', html)
    assert imgs and imgs[0].startswith("data:image/png;base64,")
    assert html.index("<img") < html.index("What each part ran on") < html.index("Claims on real data")
    assert html.count("What each part ran on") == 1
    assert "align-items:flex-start" in html  # the page opens at its top, not centred on its middle
    # every claim's id links to an anchor that exists, and the full texts are there
    for cid in claims["id"]:
        a = claim_anchor(cid)
        assert f'href="#{a}"' in html and f'id="{a}"' in html, cid
    assert " ".join(LONG_EVIDENCE.split()) in " ".join(html.split())
    # the compare section shows its key figure (scaled down to the page) with its caption
    side = html[html.index("The generators side by side"):]
    assert "data:image/png;base64," in side and "boxes" in side


def test_a_familys_sanity_checks_file_is_marked_apart_and_not_counted(tmp_path):
    """Rows of compare/sanity_checks.csv (claims true by construction) reach claims.csv marked as sanity
    checks: the scoreboard draws them apart and leaves them out of the counts; verdicts.csv rows are findings."""
    paths, real, data, _ = _run(tmp_path)
    sanity = tmp_path / "compare" / "sanity_checks.csv"
    pd.DataFrame([{"claim": "re-sequencers copy frames (novelty 0)", "paper_value": "", "ours": "0 m",
                   "data": "", "verdict": "reproduced", "evidence": "by construction", "source": ""}]).to_csv(
        sanity, index=False)
    claims = claims_table(paths + [sanity], data, real)
    marked = claims.set_index("claim")["sanity_check"]
    assert bool(marked["re-sequencers copy frames (novelty 0)"])
    assert not marked.drop("re-sequencers copy frames (novelty 0)").any()
    assert list(sanity_checks(claims)) == list(claims["sanity_check"])
    counts = scoreboard_counts(claims)
    without = scoreboard_counts(claims_table(paths, data, real))
    assert counts.set_index("family").loc["compare", "sanity_checks"] == 1
    pd.testing.assert_frame_equal(counts.drop(columns="sanity_checks").reset_index(drop=True),
                                  without.drop(columns="sanity_checks").reset_index(drop=True))


#: a line between the provenance table and the scoreboard is at most this long (a sentence, not a list of paths)
SHORT_LINE = 200


def _scoreboard_rows(md: str) -> dict[str, list[str]]:
    """The scoreboard's counts table as {paper: cells}, with its header's column names under ''."""
    sb = md[md.index("## Scoreboard"): md.index("## Claims of the four papers")]
    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in sb.splitlines() if ln.startswith("| ")]
    return {"": rows[0], **{r[0]: r for r in rows[1:]}}


def _counts_in_words(text: str) -> dict[str, int]:
    """'2 partly, 6 within noise; 2 sanity checks.' -> {'partly': 2, 'within noise': 6, 'sanity checks': 2}"""
    found = {w: int(n) for n, w in re.findall(r"(\d+) ([a-z][a-z ]*?)(?=[,;.]|$)", text)}
    if "sanity check" in found:
        found["sanity checks"] = found.pop("sanity check")
    return found


@pytest.mark.parametrize("sanity", [False, True])
def test_family_headers_count_as_the_scoreboard_does_sanity_checks_apart(tmp_path, sanity):
    md, claims = _summary(tmp_path, sanity=sanity)
    board = _scoreboard_rows(md)
    header = board[""]
    for fam in claims["family"].unique():
        section = md[md.index("## " + FAMILY_SECTION[fam]):]
        line = next(ln for ln in section.splitlines() if ln.startswith("**Data:**"))
        said = _counts_in_words(line[line.index("Claims "):].split(": ", 1)[1])
        row = board[str(claims.loc[claims["family"] == fam, "paper"].iloc[0])]
        table = {h: int(v) for h, v in zip(header, row) if h not in ("paper", "data", "claims") and int(v or 0)}
        assert said == table, (fam, line, row)
    comp = md[md.index("## " + FAMILY_SECTION["compare"]):]
    line = next(ln for ln in comp.splitlines() if ln.startswith("**Data:**"))
    if sanity:  # two findings reproduced, two sanity checks apart, never counted as reproduced
        assert line.endswith("Claims C1 to C4: 2 reproduced; 2 sanity checks."), line
        assert board[""][-1] == "sanity checks" and board[str(claims.loc[claims["family"] == "compare", "paper"]
                                                            .iloc[0])][-1] == "2"
    else:
        assert line.endswith("Claims C1 to C2: 2 reproduced."), line
    # the claims table's count lines, on real and on synthetic data, add up to the scoreboard's rows
    for title, real in (("### On real data", True), ("### On synthetic data", False)):
        block = md[md.index(title):].split("\n\n")[1]
        assert block == verdict_counts_md(claims[claims["real"] == real])
        want: dict[str, int] = {}
        for _, c in claims[claims["real"] == real].drop_duplicates("family").iterrows():
            row = board[str(c["paper"])]
            for h, v in zip(header, row):
                if h not in ("paper", "data", "claims") and int(v or 0):
                    want[h] = want.get(h, 0) + int(v)
        assert _counts_in_words(block) == want, (title, block)


def test_only_short_lines_between_provenance_and_scoreboard_and_every_timing_table_named_later(tmp_path):
    md, _ = _summary(tmp_path)
    lines = md.splitlines()
    last_prov = max(i for i, ln in enumerate(lines[: lines.index("## Scoreboard")]) if ln.startswith("| "))
    between = lines[last_prov + 1: lines.index("## Scoreboard")]
    assert SOURCE_NOTE in between  # the sentence on what the numbers are computed on stays where it was
    assert all(len(ln) <= SHORT_LINE for ln in between), [len(ln) for ln in between]
    assert not any(t in "\n".join(between) for t in TIMING)
    # every timing table is named, after the claims table and the families' sections: the summary's last section
    tail = md[md.index("## Timing tables"):]
    assert md.index("## Timing tables") > md.index("## Detailed tables") > md.index("## Claims of the four papers")
    assert "\n## " not in tail[3:]
    for t in TIMING:
        assert f"- `{t}`" in tail.splitlines(), t
        assert md.count(t) == 1, t
    assert "(#timing-tables)" in "\n".join(between)  # and the short line above points there
    # no timing table, no section and no pointer
    paths, real, data, prov = _run(tmp_path)
    plain = build_summary([], paths, SOURCE_NOTE, prov, data, real, False)
    assert "Timing tables" not in plain and "timing" not in plain.lower()


def test_the_long_track_claims_are_a_scoreboard_row_of_their_own(tmp_path):
    """The comparison's claims decided on the long track's table (their ``source``, report.ROW_PARTS) keep their
    family and ids but carry a paper label of their own, and the scoreboard draws and counts them as a row of
    their own after the 2-s claims' row."""
    from animsynth.report import ROW_PARTS

    paths, real, data, _ = _run(tmp_path)
    comp = pd.read_csv(paths[-1], dtype=str, keep_default_na=False)
    long_source = next(iter(ROW_PARTS))
    extra = [{**comp.iloc[0].to_dict(), "claim": f"long claim {i}", "verdict": v, "source": long_source}
             for i, v in enumerate(["undecided", "reproduced", "contradicted"])]
    pd.concat([comp, pd.DataFrame(extra)], ignore_index=True).to_csv(paths[-1], index=False)
    claims = claims_table(paths, data, real)
    is_long = claims["source"] == long_source
    assert list(claims.loc[claims["family"] == "compare", "id"]) == ["C1", "C2", "C3", "C4", "C5"]
    assert claims.loc[is_long, "paper"].str.endswith(": " + ROW_PARTS[long_source]).all()
    assert claims.loc[(claims["family"] == "compare") & ~is_long, "paper"].nunique() == 1
    counts = scoreboard_counts(claims)
    comp_rows = counts[counts["family"] == "compare"]
    assert list(comp_rows["claims"]) == [2, 3]
    assert comp_rows.iloc[1][["reproduced", "contradicted"]].tolist() == [1, 1]
    assert comp_rows.iloc[1]["paper"].endswith(ROW_PARTS[long_source])
    fig, drawn = draw_scoreboard(claims)
    try:
        assert list(drawn["paper"]) == list(counts["paper"])
        names = {t.get_text() for t in fig.axes[0].texts}
        assert set(counts["paper"]) <= names  # one row heading per row, the long track's included
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
