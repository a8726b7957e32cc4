"""The Snakemake report of the tiny run: self-contained, opens on the papers' claims, and every
embedded table and image decodes."""

import base64
import io
import json
import re

import pandas as pd
import pytest
from PIL import Image

from conftest import run_snakemake

pytestmark = pytest.mark.workflow


def _embedded_results(html: str) -> dict:
    m = re.search(r"var results = (\{.*?\});\s*</script>", html, re.S)
    assert m, "no embedded results in the report"
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
