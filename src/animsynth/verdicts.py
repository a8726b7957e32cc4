"""The one verdict format of every family: columns, vocabulary, a row builder that refuses unknown words.

Every family writes ``<family>/verdicts.csv`` with the columns :data:`COLUMNS`, one row per claim:

``claim``
    what the paper (or a study beyond it) claims, in words.
``paper_value``
    the paper's number or statement ('' when it publishes none).
``ours``
    our number, computed by the code on the data in ``data``.
``data``
    what the numbers ran on (clips, folds, seeds).
``verdict``
    one word of :data:`VOCABULARY`.
``evidence``
    the spread and the test behind the verdict (shares across seeds, folds or starts).
``source``
    the table or figure of this run that holds the numbers.

The vocabulary:

* ``reproduced`` -- the claim holds on every nudge (seeds, folds, starts) tested;
* ``partly`` -- it holds for some of the cases the claim covers and not others, each of them stably;
* ``not reproduced`` -- the effect is absent or the number out of range, stably;
* ``contradicted`` -- the opposite holds on every nudge;
* ``within noise`` -- the outcome flips across nudges; the evidence gives the share.

Whether a row ran on real or synthetic data is not part of the row: the data layer records it
per family (``FAMILY_REAL`` of the workflow) and the report joins it, so no word in a text decides it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["COLUMNS", "VOCABULARY", "VerdictError", "row", "table", "read", "check", "fmt", "agreement_verdict",
           "holm"]

COLUMNS = ("claim", "paper_value", "ours", "data", "verdict", "evidence", "source")
VOCABULARY = ("reproduced", "partly", "not reproduced", "contradicted", "within noise")


class VerdictError(ValueError):
    """A verdict row or table that breaks the common format."""


def _text(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float) and not np.isfinite(v):
        return "nan"
    return str(v)


def row(claim: str, verdict: str, evidence: str = "", *, paper_value="", ours="", data: str = "",
        source: str = "") -> dict[str, str]:
    """One verdict row as a dict of the :data:`COLUMNS` (every value a string).

    Raises
    ------
    VerdictError
        when ``verdict`` is not a word of :data:`VOCABULARY` or ``claim`` is empty.
    """
    if verdict not in VOCABULARY:
        raise VerdictError(f"verdict {verdict!r} for claim {claim!r} is not one of {list(VOCABULARY)}")
    if not str(claim or "").strip():
        raise VerdictError("a verdict row needs a claim")
    return {"claim": _text(claim), "paper_value": _text(paper_value), "ours": _text(ours), "data": _text(data),
            "verdict": verdict, "evidence": _text(evidence), "source": _text(source)}


def check(df: pd.DataFrame, where: str = "verdict table") -> pd.DataFrame:
    """Validate a verdict table: exactly the :data:`COLUMNS`, vocabulary words, a claim in each row.

    ``where`` names the table in the error (a path). The row number in the message is the CSV line
    (header = line 1). Returns the table with the columns in order.
    """
    missing = [c for c in COLUMNS if c not in df.columns]
    extra = [c for c in df.columns if c not in COLUMNS]
    if missing or extra:
        raise VerdictError(f"{where}: columns must be {list(COLUMNS)}; missing {missing}, unexpected {extra}")
    for i, (claim, verdict) in enumerate(zip(df["claim"], df["verdict"])):
        if verdict not in VOCABULARY:
            raise VerdictError(f"{where}, line {i + 2}: verdict {verdict!r} is not one of {list(VOCABULARY)}")
        if not str(claim).strip():
            raise VerdictError(f"{where}, line {i + 2}: empty claim")
    return df[list(COLUMNS)]


def table(rows: Iterable[Mapping[str, str]]) -> pd.DataFrame:
    """Rows (from :func:`row`) -> a checked verdict table with the :data:`COLUMNS` in order."""
    df = pd.DataFrame(list(rows), columns=list(COLUMNS))
    return check(df.fillna(""))


def read(path) -> pd.DataFrame:
    """Read and check ``<family>/verdicts.csv`` (every cell a string; errors name the file and line)."""
    p = Path(path)
    try:
        df = pd.read_csv(p, keep_default_na=False, dtype=str)
    except pd.errors.EmptyDataError:
        raise VerdictError(f"{p}: empty verdict file") from None
    return check(df, str(p))


def fmt(x, nd: int = 3) -> str:
    """A number for a verdict text: ``nd`` significant digits; 'nan' for None or a non-finite value."""
    if x is None:
        return "nan"
    x = float(x)
    return "nan" if not np.isfinite(x) else f"{x:.{nd}g}"


def agreement_verdict(share: float) -> str:
    """Verdict from the share of nudges (seeds, folds, members) on which a claim holds.

    ``reproduced`` when all agree, ``contradicted`` when none does, ``within noise`` in between,
    ``not reproduced`` when there is no share (no comparable case).
    """
    if share is None or not np.isfinite(share):
        return "not reproduced"
    if share == 1.0:
        return "reproduced"
    if share == 0.0:
        return "contradicted"
    return "within noise"


def holm(pvalues) -> np.ndarray:
    """Holm's step-down adjustment of a family of p-values (Holm 1979): the ``i``-th smallest is multiplied by
    ``m - i`` (``i`` from 0, ``m`` the finite p-values), made monotone and capped at 1. A claim is significant
    at ``alpha`` when its adjusted p is below ``alpha``. NaN stays NaN (no test) and does not count in ``m``."""
    p = np.asarray(list(pvalues), float)
    out = np.full(p.shape, np.nan)
    ok = np.flatnonzero(np.isfinite(p))
    m = ok.size
    if m == 0:
        return out
    order = ok[np.argsort(p[ok], kind="stable")]
    adj = np.minimum(1.0, np.maximum.accumulate(p[order] * (m - np.arange(m))))
    out[order] = adj
    return out
