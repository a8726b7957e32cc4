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
* ``within noise`` -- the outcome flips across nudges; the evidence gives the share;
* ``undecided`` -- too few independent units, or too wide an interval, to decide either way; the evidence gives
  the effect and its interval (the generators side by side use it; no other family emits it).

A beats B over units
--------------------
Families that decide "A beats B" over independent units (pairs of paths) use one rule, :func:`a_beats_b`: each
unit votes for A, for B or for neither (:func:`unit_votes`: a unit votes only when it leans one way by at least
the minimum effect); A *holds* when at least ``share`` of the units vote for it and a test of the votes gives
``p < alpha`` (the two-sided sign test, :func:`sign_test`, unless the family gives its own p, or its own test's
decision as ``significant``); *opposite* is the same for B; a significant test without the share *leans*;
anything else is noise. A family whose lead for A must also survive resampling passes ``stable``. Each family
maps the outcome onto :data:`VOCABULARY` and says in its evidence how many units voted which way.

Holds on all, some or none
--------------------------
A claim checked on several cases (configurations, edits, sequences) is ``reproduced`` when it holds on every
case, ``partly`` on some and otherwise the family's word for none (``not reproduced`` or ``contradicted``):
:func:`share_verdict`. The generators side by side
decide their declared claims over groups of clips by the mean group effect, an exact sign-flip test and its
interval instead (:mod:`animsynth.compare.verdicts`), which is where ``undecided`` comes from.

Whether a row ran on real or synthetic data is not part of the row: the data layer records it
per family (``FAMILY_REAL`` of the workflow) and the report joins it, so no word in a text decides it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["COLUMNS", "VOCABULARY", "OUTCOMES", "VerdictError", "row", "table", "read", "check", "fmt",
           "agreement_verdict", "share_outcome", "share_verdict", "holm", "unit_votes", "sign_test", "a_beats_b"]

COLUMNS = ("claim", "paper_value", "ours", "data", "verdict", "evidence", "source")
VOCABULARY = ("reproduced", "partly", "not reproduced", "contradicted", "within noise", "undecided")
#: What :func:`a_beats_b` decides (the families map these onto :data:`VOCABULARY`).
OUTCOMES = ("holds", "opposite", "lean", "lean_opposite", "noise", "none")


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


def share_outcome(ok) -> str:
    """Whether a claim checked case by case holds on ``"all"`` cases, ``"some"`` or ``"none"``.

    Parameters
    ----------
    ok : array-like of bool (cases,)
        Whether the claim holds on each case (no case: ``"all"``, as ``all`` of nothing).
    """
    ok = np.asarray(ok, bool)
    return "all" if ok.all() else ("some" if ok.any() else "none")


def share_verdict(ok, none: str = "not reproduced") -> str:
    """Verdict of a claim checked case by case: ``reproduced`` when it holds on every case, ``partly`` on some,
    ``none`` on none.

    Parameters
    ----------
    ok : array-like of bool (cases,)
        Whether the claim holds on each case (no case: ``reproduced``, as ``all`` of nothing).
    none : str
        The word when it holds on no case: a word of :data:`VOCABULARY` (``not reproduced``, ``contradicted``,
        ``within noise`` when every case said so, or ``partly`` when a case short of the claim's margin does not
        contradict it).

    Raises
    ------
    VerdictError
        when ``none`` is not a word of :data:`VOCABULARY`.
    """
    if none not in VOCABULARY:
        raise VerdictError(f"verdict {none!r} is not one of {list(VOCABULARY)}")
    return {"all": "reproduced", "some": "partly", "none": none}[share_outcome(ok)]


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


def unit_votes(lead, effect=None, min_effect: float = 0.0) -> np.ndarray:
    """Each unit's vote: +1 for A, -1 for B, 0 for neither.

    Parameters
    ----------
    lead : array (units,)
        Which way the unit leans: positive towards A, negative towards B (a difference signed so that positive
        favours A, or a count of sub-units for A minus those for B).
    effect : array (units,), optional
        The unit's effect in the claim's units, signed as ``lead``; ``None``: ``lead`` itself.
    min_effect : float
        A unit votes for A when it leans to A and ``effect >= min_effect``, for B when it leans to B and
        ``effect <= -min_effect`` (a NaN effect never votes).

    Returns
    -------
    ndarray of int (units,)
    """
    lead = np.asarray(lead, float)
    effect = lead if effect is None else np.asarray(effect, float)
    m = float(min_effect)
    return np.where((lead > 0) & (effect >= m), 1, np.where((lead < 0) & (effect <= -m), -1, 0))


def sign_test(wins: int, losses: int) -> float:
    """Two-sided sign test of ``wins`` against ``losses`` (exact binomial, p = 1/2; units voting for neither are
    not counted); 1.0 when no unit votes."""
    wins, losses = int(wins), int(losses)
    if not wins + losses:
        return 1.0
    from scipy.stats import binomtest  # here, not at import (scipy.stats is slow to import)

    return float(binomtest(wins, wins + losses, 0.5).pvalue)


def a_beats_b(wins: int, losses: int, undecided: int = 0, *, share: float, alpha: float | None = None,
              p: float | None = None, significant: bool | None = None, stable: bool = True,
              min_units: int = 0) -> str:
    """The one rule for "A beats B over units": a word of :data:`OUTCOMES`.

    Parameters
    ----------
    wins, losses : int
        Units voting for A and for B (:func:`unit_votes`).
    undecided : int
        Units voting for neither that still count in the share (a unit below the minimum effect); units a
        family drops (exact ties) are not passed.
    share : float
        The share of the counted units (``wins + losses + undecided``) that must vote one way.
    alpha : float, optional
        The test's level (needed unless ``significant`` is given).
    p : float, optional
        The test's p; default the sign test of ``wins`` against ``losses`` (:func:`sign_test`). A NaN p is
        never significant.
    significant : bool, optional
        The decision of a family's own test that gives no p (e.g. "the mean margin exceeds the spread of the
        units' margins"), in place of ``p < alpha``; ``p`` and ``alpha`` are then not given.
    stable : bool
        Whether A's lead survives the family's resampling (e.g. a bootstrap share of at least 95 %); when
        False, a significant lead for A with the share reached is ``lean``, not ``holds``. B's side needs no
        resampling: a significant lead for B with the share reached is ``opposite`` either way.
    min_units : int
        Fewer counted units than this are never significant.

    Returns
    -------
    ``"holds"`` (A: share reached, significant, stable), ``"opposite"`` (the same for B), ``"lean"`` /
    ``"lean_opposite"`` (significant, the share not reached or A's lead not stable; by which side has more
    votes), ``"noise"`` (otherwise), ``"none"`` (no unit counted).

    Raises
    ------
    ValueError
        when neither ``alpha`` nor ``significant`` is given, or ``significant`` comes with ``p`` or ``alpha``.
    """
    if significant is None and alpha is None:
        raise ValueError("a_beats_b needs the test's level alpha or the family's own test decision significant")
    if significant is not None and (p is not None or alpha is not None):
        raise ValueError("a_beats_b: give either significant or p / alpha, not both")
    n = int(wins) + int(losses) + int(undecided)
    if n == 0:
        return "none"
    if significant is None:
        p = sign_test(wins, losses) if p is None else float(p)
        significant = bool(np.isfinite(p)) and p < float(alpha)
    significant = n >= int(min_units) and bool(significant)
    if significant and stable and wins / n >= float(share):
        return "holds"
    if significant and losses / n >= float(share):
        return "opposite"
    if significant:
        return "lean" if wins > losses else "lean_opposite"
    return "noise"
