"""The one verdict format of every family: columns, the words and their one meaning each, the shared rules.

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

The words
---------
:data:`WORDS` holds every verdict word with the one sentence of what it means; :data:`VOCABULARY` is its keys, and
:func:`row`, :func:`table`, :func:`check` refuse any other word. A family's rule never picks a word: it names
what happened, an **outcome** (:data:`OUTCOME_WORDS`), and :func:`word` turns the outcome into the word, the same
word in every family. So "no case at all" or "no unit voted" (outcome ``none``) is ``undecided`` everywhere, never
``reproduced`` nor ``not reproduced``; "the thing did not run" (``did_not_run``) is ``did not run``.

The rules
---------
* :func:`a_beats_b` -- "A beats B over units" (resequencing's path pairs, meshdetail's blocks with its margin test
  as ``significant``, facegraph's trend with Spearman's p and the bootstrap as ``stable``): each unit votes for A,
  for B or neither (:func:`unit_votes`, :func:`sign_test`); the outcome is one of :data:`OUTCOMES`.
* :func:`share_verdict` (with :func:`share_outcome`) -- a claim checked case by case: every case, some, none, or
  no case at all.
* :func:`agreement_verdict` -- the share of nudges (seeds, folds, starts) on which a claim holds.
* :func:`effect_verdict` -- a declared comparison over independent units (the generators side by side: subjects):
  significant in the claimed direction by at least its margin, the other way, equivalent (the 90 % interval inside
  the margins, TOST), a significant split, or undecided with the subjects 80 % power would need
  (:func:`units_for_power`). Its statistics (the unit effects, their p, Holm) are the caller's.
* :func:`ladder` / :func:`ladder_why` -- every other ladder of thresholds or conditions (the first rung that holds
  gives the outcome), so that a family writes its conditions, never its words.
* :func:`holm` -- Holm's step-down adjustment; :func:`t_interval` -- the t interval of a mean.

Whether a row ran on real or synthetic data is not part of the row: the data layer records it
per family (``FAMILY_REAL`` of the workflow) and the report joins it, so no word in a text decides it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["COLUMNS", "WORDS", "VOCABULARY", "OUTCOMES", "OUTCOME_WORDS", "VerdictError", "row", "table", "read",
           "check", "fmt", "word", "ladder", "ladder_why", "agreement_verdict", "share_outcome", "share_verdict",
           "holm", "unit_votes", "sign_test", "a_beats_b", "t_interval", "units_for_power", "power_text",
           "effect_verdict", "words_markdown"]

COLUMNS = ("claim", "paper_value", "ours", "data", "verdict", "evidence", "source")
#: every verdict word -> the one sentence of what it means (docs/compare/verdicts.md renders this table)
WORDS = {
    "reproduced": "the claim holds: significant in the claimed direction with the mean effect at least its margin "
                  "(a declared comparison), or it holds on every nudge or case tested",
    "partly": "it holds for some of the cases or units the claim covers and not for others, each side significantly "
              "or stably (a significant split, or a significant lead whose share of units falls short)",
    "no material difference": "equivalence shown: the 90 % interval of the effect lies inside plus or minus the "
                              "declared margin",
    "within noise": "the outcome flips across nudges (seeds, folds, starts, resamples): stable neither way",
    "undecided": "the data cannot decide: too few units, too wide an interval, or no case at all",
    "not reproduced": "a published number or result is not reached, stably; never said for a lack of evidence",
    "contradicted": "the opposite holds, in the same way",
    "did not run": "the method, generator or data did not run: no evidence; the evidence says why",
}
VOCABULARY = tuple(WORDS)
#: what happened -> its word: a rule names the outcome, :func:`word` gives the word
OUTCOME_WORDS = {
    "holds": "reproduced",             # significant (or on every case / nudge) in the claimed direction
    "opposite": "contradicted",        # the same the other way
    "equivalent": "no material difference",
    "split": "partly",                 # some units or cases for and some against, each side significantly / stably
    "lean": "partly",                  # a significant lead for A whose share of units falls short
    "lean_opposite": "partly",         # a significant lead for B whose share of units falls short
    "short": "not reproduced",         # a value claim: the published number or result not reached, stably
    "unstable": "within noise",        # significant, but the lead flips under the family's resampling
    "flips": "within noise",           # the outcome flips across nudges
    "noise": "undecided",              # no significant lead either way
    "none": "undecided",               # no unit voted, no case, no number to decide on
    "did_not_run": "did not run",
}
#: What :func:`a_beats_b` decides (:func:`word` maps each onto :data:`VOCABULARY`).
OUTCOMES = ("holds", "opposite", "lean", "lean_opposite", "unstable", "noise", "none")


class VerdictError(ValueError):
    """A verdict row or table that breaks the common format."""


def word(outcome: str) -> str:
    """The verdict word of an outcome of :data:`OUTCOME_WORDS` (the one mapping every family uses).

    Raises
    ------
    VerdictError
        for an outcome that is not a key of :data:`OUTCOME_WORDS`.
    """
    try:
        return OUTCOME_WORDS[outcome]
    except (KeyError, TypeError):
        raise VerdictError(f"outcome {outcome!r} is not one of {list(OUTCOME_WORDS)}") from None


def ladder_why(rungs, otherwise, *, evidence: bool = True, missing: str = "no evidence") -> tuple[str, str]:
    """The word and reason of the first rung whose condition holds.

    Parameters
    ----------
    rungs : iterable of (condition, outcome, reason)
        In order; ``condition`` a bool, ``outcome`` a key of :data:`OUTCOME_WORDS`, ``reason`` the words of why.
    otherwise : (outcome, reason)
        When no rung holds.
    evidence : bool
        False: no case, no number to decide on: ``undecided`` with ``missing`` as the reason, whatever the rungs.

    Returns
    -------
    (word, reason)
    """
    if not evidence:
        return word("none"), missing
    for ok, outcome, why in rungs:
        if bool(ok):
            return word(outcome), why
    return word(otherwise[0]), otherwise[1]


def ladder(rungs, otherwise: str, *, evidence: bool = True) -> str:
    """The word of the first rung ``(condition, outcome)`` that holds, else of ``otherwise`` (an outcome);
    ``undecided`` without ``evidence`` (:func:`ladder_why` without the reasons)."""
    return ladder_why(((ok, out, "") for ok, out in rungs), (otherwise, ""), evidence=evidence)[0]


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


def words_markdown() -> str:
    """The words and their meanings (:data:`WORDS`) as a Markdown table (docs/compare/verdicts.md)."""
    lines = ["| word | what it means |", "|---|---|"]
    lines += [f"| {w} | {meaning} |" for w, meaning in WORDS.items()]
    return "\n".join(lines)


def agreement_verdict(share: float) -> str:
    """Verdict from the share of nudges (seeds, folds, members) on which a claim holds: every nudge ``holds``
    (``reproduced``), none ``opposite`` (``contradicted``), in between ``flips`` (``within noise``); no share (no
    comparable case) ``none`` (``undecided``)."""
    finite = share is not None and bool(np.isfinite(share))
    return ladder([(finite and share == 1.0, "holds"), (finite and share == 0.0, "opposite")], "flips",
                  evidence=finite)


def share_outcome(ok) -> str:
    """Whether a claim checked case by case holds on ``"all"`` cases, ``"some"``, ``"none"``, or there is no case
    (``"empty"``).

    Parameters
    ----------
    ok : array-like of bool (cases,)
        Whether the claim holds on each case.
    """
    ok = np.asarray(ok, bool)
    if not ok.size:
        return "empty"
    return "all" if ok.all() else ("some" if ok.any() else "none")


def share_verdict(ok, none: str = "short") -> str:
    """Verdict of a claim checked case by case: ``reproduced`` when it holds on every case, ``partly`` on some, the
    word of the outcome ``none`` on none, ``undecided`` without a case.

    Parameters
    ----------
    ok : array-like of bool (cases,)
        Whether the claim holds on each case.
    none : str
        The outcome (:data:`OUTCOME_WORDS`) when it holds on no case: ``short`` (a number or result not reached:
        ``not reproduced``), ``opposite`` (the opposite holds on every case: ``contradicted``), ``flips`` (every
        case said within noise) or ``split`` (a case short of the claim's margin that does not contradict it).

    Raises
    ------
    VerdictError
        when ``none`` is not an outcome of :data:`OUTCOME_WORDS`.
    """
    word(none)  # checked whatever the cases say
    kind = share_outcome(ok)
    return ladder([(kind == "all", "holds"), (kind == "some", "split")], none, evidence=kind != "empty")


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
    """The one rule for "A beats B over units": an outcome of :data:`OUTCOMES` (:func:`word` gives its word).

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
        False, a significant lead for A with the share reached is ``unstable``, not ``holds``. B's side needs no
        resampling: a significant lead for B with the share reached is ``opposite`` either way.
    min_units : int
        Fewer counted units than this are never significant.

    Returns
    -------
    ``"holds"`` (A: share reached, significant, stable: ``reproduced``), ``"opposite"`` (the same for B:
    ``contradicted``), ``"unstable"`` (A's significant lead with the share reached flips under resampling:
    ``within noise``), ``"lean"`` / ``"lean_opposite"`` (significant, the share not reached, by which side has more
    votes: ``partly``), ``"noise"`` (not significant: ``undecided``), ``"none"`` (no unit counted: ``undecided``).

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
    if significant and wins / n >= float(share):
        return "unstable"
    if significant:
        return "lean" if wins > losses else "lean_opposite"
    return "noise"


@lru_cache(maxsize=512)
def _t_quantile(q: float, df: int) -> float:
    """scipy's t quantile, cached: the tables ask for the same few (level, units) pairs hundreds of times."""
    from scipy.stats import t

    return float(t.ppf(q, df))


def t_interval(effects, level: float = 0.95) -> tuple[float, float]:
    """The ``level`` t interval of the mean of ``effects`` (mean +- t(1 - (1 - level) / 2, n - 1) x sd / sqrt(n));
    NaN for fewer than 2 finite values."""
    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    if e.size < 2:
        return float("nan"), float("nan")
    half = _t_quantile(1 - (1 - level) / 2, int(e.size - 1)) * float(e.std(ddof=1)) / np.sqrt(e.size)
    return float(e.mean() - half), float(e.mean() + half)


#: the largest number of units :func:`units_for_power` looks at
MAX_POWER_UNITS = 1000


def units_for_power(effects, alpha: float = 0.05, power: float = 0.8, max_units: int = MAX_POWER_UNITS) -> float:
    """How many independent units a two-sided one-sample t test at level ``alpha`` would need to reach ``power``
    if the true effect were the observed one (effect size: mean / sd of ``effects``).

    The power at n units is P(|T| > t(1 - alpha / 2, n - 1)) for T noncentral t with n - 1 degrees of freedom
    and noncentrality (mean / sd) x sqrt(n) (scipy's ``nct``); the smallest n from 2 with that power is
    returned.

    Returns
    -------
    float: that n; ``inf`` beyond ``max_units``; NaN with fewer than 2 finite effects or a mean of 0. Equal non-zero
    effects (sd 0) give 2.
    """
    from scipy.stats import nct, t

    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    if e.size < 2 or float(e.mean()) == 0.0:
        return float("nan")
    sd = float(e.std(ddof=1))
    if sd == 0.0:
        return 2.0
    n = np.arange(2, int(max_units) + 1)
    df = n - 1
    crit = t.ppf(1 - float(alpha) / 2, df)
    nc = abs(float(e.mean())) / sd * np.sqrt(n)
    got = nct.sf(crit, df, nc) + nct.cdf(-crit, df, nc)
    hit = np.flatnonzero(got >= float(power))
    return float(n[hit[0]]) if hit.size else math.inf


def power_text(effects, alpha: float = 0.05, power: float = 0.8) -> str:
    """:func:`units_for_power` in words: the number, ``">1000"`` beyond :data:`MAX_POWER_UNITS`, ``"no effect
    observed"`` at a mean of 0, ``""`` with fewer than 2 units."""
    e = np.asarray(effects, float)
    e = e[np.isfinite(e)]
    if e.size and float(e.mean()) == 0.0:
        return "no effect observed"
    n = units_for_power(e, alpha, power)
    if not np.isfinite(n):
        return f">{MAX_POWER_UNITS}" if n == math.inf else ""
    return str(int(n))


def effect_verdict(*, n: int, mean: float, p_holm: float, ci90: tuple[float, float], margin: float, alpha: float,
                   min_units: int, split: tuple[int, int] = (0, 0), missing: str = "",
                   units: str = "subjects") -> tuple[str, str]:
    """The rule of a declared comparison over independent units, checked in this order.

    ``did not run`` (``missing``: why a side has no value at all); ``reproduced`` (at least ``min_units`` units,
    ``p_holm < alpha`` and ``mean >= margin``); ``contradicted`` (the same with ``mean <= -margin``); ``no material
    difference`` (at least ``min_units`` units and the 90 % interval ``ci90`` strictly inside (-margin, +margin): two
    one-sided tests at 5 %); ``partly`` (a significant split: ``split`` = units significantly for, against, both
    non-zero); otherwise ``undecided``, saying why (no unit, too few, significant but below the margin, or neither
    significant nor equivalent).

    Parameters
    ----------
    n : units with an effect
    mean : their mean effect, signed so that positive favours the claim
    p_holm : its Holm-adjusted p (NaN: no test)
    ci90 : the 90 % interval of the mean effect (NaN with fewer than 2 units)
    margin : the smallest effect that matters (> 0), in the effect's units
    alpha, min_units : the level and the fewest units that can be significant (or equivalent)
    split : (units significantly for, units significantly against) by per-unit tests
    missing : '' when both sides ran; else why not
    units : the units' name in the reasons

    Returns
    -------
    (word, reason)
    """
    if missing:
        return word("did_not_run"), missing
    lo, hi = (float(x) for x in ci90)
    enough = int(n) >= int(min_units)
    sig = enough and bool(np.isfinite(p_holm)) and float(p_holm) < float(alpha)
    inside = enough and bool(np.isfinite(lo) and np.isfinite(hi)) and -margin < lo and hi < margin
    n_for, n_against = (int(x) for x in split)
    if sig:
        why = (f"significant but the mean effect {fmt(mean)} is below the margin {fmt(margin)} and its 90 % interval "
               "is not inside plus or minus the margin")
    elif not enough:
        why = f"{int(n)} {units}, fewer than the {int(min_units)} a test needs"
    else:
        why = "neither significant (Holm) nor equivalent (the 90 % interval not inside plus or minus the margin)"
    return ladder_why([
        (sig and mean >= margin, "holds", "significant (Holm) and the mean effect at least the margin"),
        (sig and mean <= -margin, "opposite", "significant (Holm) the other way, the mean effect at least the margin"),
        (inside, "equivalent", f"the 90 % interval ({fmt(lo)}, {fmt(hi)}) lies inside plus or minus the margin "
                               f"{fmt(margin)} (two one-sided tests at 5 %)"),
        (n_for and n_against, "split", f"a significant split: {n_for} {units} significantly for and {n_against} "
                                       "significantly against"),
    ], ("noise", why), evidence=int(n) > 0, missing=f"no {units[:-1] if units.endswith('s') else units} with a value")
