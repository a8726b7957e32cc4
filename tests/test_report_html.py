"""The Snakemake report of the tiny run: self-contained, opens at the top on the scoreboard (whose counts are
claims.csv's), then the papers' claims, and every embedded table and image decodes."""

import base64
import io
import json
import re

import pandas as pd
import pytest
from PIL import Image

from animsynth.scoreboard import sanity_checks
from conftest import run_snakemake

pytestmark = pytest.mark.workflow


def _embedded_results(html: str) -> dict:
    m = re.search(r"var results = (\{.*?\});\s*</script>", html, re.S)
    assert m, "no embedded results in the report"
    return json.loads(m.group(1))


def _home_page(html: str) -> str:
    m = re.search(r"var workflow_desc = (\".*?\");\s*</script>", html, re.S)
    assert m, "no home page in the report"
    return json.loads(m.group(1))


def test_report_opens_on_claims_and_every_embedded_file_decodes(tiny_workflow, tmp_path):
    # written outside the shared run's results/, which other tests compare file by file
    report = tmp_path / "report.html"
    res = run_snakemake(tiny_workflow, "--configfile", "config/test.yaml", "--report", str(report))
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    html = report.read_text()
    # self-contained: nothing is fetched from disk or the network when it opens
    assert not re.search(r'<(img|script|link)[^>]+(src|href)="(?!data:|#|javascript:)[^"]+"', html)
    assert "Claims on synthetic data" in html and "What each part ran on" in html
    # the home page opens at its top (not centred on its middle) on the banner and the scoreboard: its first
    # picture, before any table or list of the page
    home = _home_page(html)
    assert "align-items:flex-start" in home
    first = re.search(r"<(img|table|ul)\b", home)
    assert first and first.group(1) == "img" and 'alt="Scoreboard' in home[first.start():first.start() + 20000]
    assert home.count("What each part ran on") == 1
    # the scoreboard's counts are claims.csv's (findings per verdict; sanity checks apart)
    res = tiny_workflow / "results"
    claims = pd.read_csv(res / "claims.csv", keep_default_na=False)
    counts = pd.read_csv(res / "scoreboard.csv")
    assert counts["claims"].sum() + counts["sanity_checks"].sum() == len(claims)
    sanity = sanity_checks(claims)
    for _, row in counts.iterrows():  # a row is a family's claims of one paper label (the long track: its own)
        mine = (claims["family"] == row["family"]) & (claims["paper"] == row["paper"])
        assert row["sanity_checks"] == int((mine & sanity).sum())
        for verdict, n in claims.loc[mine & ~sanity, "verdict"].value_counts().items():
            assert row[verdict] == n, (row["family"], verdict)
    with Image.open(res / "scoreboard.png") as im:
        assert im.width >= 800
    results = _embedded_results(html)
    assert len(results) >= 30
    kinds = {}
    for path, r in results.items():
        head, _, payload = r["data_uri"].partition(";base64,")
        data = base64.b64decode(payload, validate=True)
        assert data, path
        mime = r["mime_type"]
        kinds[mime] = kinds.get(mime, 0) + 1
        if mime.startswith("image/"):
            with Image.open(io.BytesIO(data)) as im:
                im.verify()
        elif mime == "text/csv":
            df = pd.read_csv(io.BytesIO(data))
            assert len(df.columns) >= 1, path
        else:
            data.decode("utf-8")
    assert kinds.get("image/png", 0) >= 10 and kinds.get("text/csv", 0) >= 10, kinds
