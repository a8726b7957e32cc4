"""The declared claims of the comparison: read from the config (``compare.claims``, config/config.yaml alone), their
margins, their checks at config time, and their table in the docs.

* :func:`declared_claims` -- the claims of a ``compare`` block, each with its ``direction`` and ``margin`` filled in;
* :func:`margin` -- the margin of a metric or claim, read in one place: the claim's own ``min_effect``, else
  ``compare.verdicts.min_effect`` (an override per metric), else the metric's record
  (:attr:`animsynth.compare.measures.metric_table.Metric.margin`);
* :func:`check_claims` -- every claim refused at config time in one line naming ``compare.claims[i].<key>``;
* :func:`claims_markdown`, :func:`margins_markdown`, :func:`update_page` -- the declared-claims and margins tables of
  docs/compare/verdicts.md, generated from the config and the metric table (``python -m animsynth.compare.claims``
  rewrites the page; a test keeps it up to date).

The list is written once, in config/config.yaml; the schema checks the shape of a claim, this module the rest.
"""

from __future__ import annotations

import re

from ..config import ConfigError
from .measures.metric_table import KEY_COLUMNS, metric_or_blank

__all__ = ["EVERY", "claim_track", "track_claims", "declared_claims", "margin", "check_claims", "claims_markdown",
           "margins_markdown", "update_page", "page_parts"]

#: ``b`` of a claim against every generator of the run but the references (one intersection-union finding)
EVERY = "*"
#: columns of ``metrics.csv`` that are not numbers a claim can compare
_TEXT_COLUMNS = (*KEY_COLUMNS, "note")


def margin(metric: str, vc: dict | None = None, spec: dict | None = None) -> float | None:
    """The margin of ``metric`` (the smallest difference a user would care about, in its units).

    Parameters
    ----------
    metric : a column of ``metrics.csv``
    vc : the ``compare.verdicts`` block (its ``min_effect`` mapping overrides the metric table), optional
    spec : a declared claim, optional (its own ``min_effect`` comes first)

    Returns
    -------
    float, or None when neither the claim, the override nor the metric's record gives one.
    """
    if spec is not None and spec.get("min_effect") is not None:
        return float(spec["min_effect"])
    over = (vc or {}).get("min_effect") or {}
    if metric in over:
        return float(over[metric])
    m = metric_or_blank(metric).margin
    return None if m is None else float(m)


def claim_track(spec: dict) -> str:
    """The track a declared claim is decided on: its ``track`` key, ``"short"`` (the 2-s continuations) when it
    gives none."""
    return spec.get("track") or "short"


def track_claims(claims, track: str) -> list[dict]:
    """The declared claims (``compare.claims``) decided on ``track``, in order: one family of Holm's correction."""
    return [c for c in claims or [] if claim_track(c) == track]


def declared_claims(cmp: dict) -> list[dict]:
    """The declared claims of a ``compare`` block (``compare.claims``), in order, each a copy with ``direction``
    (the metric's when the claim gives none), ``margin`` (:func:`margin`), ``paper_value`` and ``note`` filled in."""
    out = []
    for spec in cmp.get("claims") or []:
        s = dict(spec)
        s["direction"] = s.get("direction") or metric_or_blank(s["metric"]).better
        s["margin"] = margin(s["metric"], cmp.get("verdicts"), s)
        s.setdefault("paper_value", "")
        s.setdefault("note", "")
        out.append(s)
    return out


def check_claims(config: dict) -> None:
    """Refuse at config time what the schema cannot see in ``compare.claims``, one line naming the key.

    An unknown track (:data:`~animsynth.compare.measures.metric_table.TRACKS`), a metric not on the claim's track,
    a long-track claim while ``compare.long_track`` is off, a long-track metric that needs a longer run than
    ``compare.long_track.seconds`` (its record's ``min_seconds``), an unknown metric, a text column (clip, seed, group,
    note, ...), an unknown generator (neither one of the
    family's rows, :data:`animsynth.compare.generators.names.GENERATORS`, nor in ``compare.user_generators``: a typo),
    ``a == b``, ``'*'`` anywhere but ``b``, a duplicate id, a metric with neither a margin nor ``min_effect``, and a
    descriptive metric (no direction in the metric table) without ``direction``.

    A family row that this run leaves out of ``compare.generators`` is no error: a run may compare fewer generators
    than the shipped claims name, and such a claim is "did not run" (not in this run), as for a row left out because
    its package is not installed.

    Raises
    ------
    ConfigError
    """
    from .generators.names import GENERATORS
    from .measures.metric_table import TRACKS, track_names

    cmp = config["compare"]
    known = set(GENERATORS) | set(cmp["generators"]) | set(cmp.get("user_generators") or {})
    seen: dict = {}
    for i, c in enumerate(cmp.get("claims") or []):
        key = f"config key 'compare.claims[{i}]"
        metric, track = c["metric"], claim_track(c)
        if track not in TRACKS:
            raise ConfigError(f"{key}.track': {track!r} is not a track (one of {', '.join(TRACKS)})")
        if track == "long" and not _long_on(cmp):
            raise ConfigError(f"{key}.track': a long-track claim while config key 'compare.long_track' is off")
        if metric in _TEXT_COLUMNS or metric not in track_names(track):
            what = ("a text column of metrics.csv" if metric in _TEXT_COLUMNS else
                    f"not a metric of the {track} track" if metric in track_names("long") + track_names("short")
                    else "not a metric")
            raise ConfigError(f"{key}.metric': {metric!r} is {what} (one of the {track} track's columns of the "
                              "metric table: compare/measures/metric_table.py)")
        for side in ("a", "b"):
            g = c[side]
            if g == EVERY and side == "a":
                raise ConfigError(f"{key}.a': '*' (every generator) may only be b")
            if g != EVERY and g not in known:
                raise ConfigError(f"{key}.{side}': {g!r} is not a generator (one of the family's rows, "
                                  "animsynth.compare.generators.names.GENERATORS, or of compare.user_generators)")
        need = metric_or_blank(metric).min_seconds
        if track == "long" and need > float(cmp["long_track"].get("seconds") or 0):
            raise ConfigError(f"{key}.metric': {metric!r} needs a run of at least {need:g} s; config key "
                              f"'compare.long_track.seconds' is {cmp['long_track'].get('seconds')}")
        if c["a"] == c["b"]:
            raise ConfigError(f"{key}.b': {c['b']!r} is also a; a claim compares two generators")
        if c["id"] in seen:
            raise ConfigError(f"{key}.id': {c['id']!r} is also compare.claims[{seen[c['id']]}].id")
        seen[c["id"]] = i
        if margin(metric, cmp.get("verdicts"), c) is None:
            raise ConfigError(f"{key}.min_effect': metric {metric!r} has no margin in the metric table; give the "
                              "claim its min_effect (the smallest effect that matters, in the metric's units)")
        if not c.get("direction") and not metric_or_blank(metric).better:
            raise ConfigError(f"{key}.direction': metric {metric!r} is descriptive (no better direction in the "
                              "metric table); say which value of a the claim expects (lower or higher)")


def _long_on(cmp: dict) -> bool:
    """Whether the ``compare`` block runs the long track (``long_track`` set and not ``enabled: false``)."""
    block = cmp.get("long_track")
    return bool(block) and bool(block.get("enabled", True))


def _md(rows: list[list[str]], head: list[str]) -> str:
    esc = lambda x: str(x).replace("|", "\\|")  # noqa: E731
    return "\n".join(["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
                     + ["| " + " | ".join(esc(x) for x in r) + " |" for r in rows])


def claims_markdown(cmp: dict) -> str:
    """The declared claims of a ``compare`` block as a Markdown table: id, track (:func:`claim_track`), claim, a, b,
    metric, direction, margin (and where it comes from), what a paper says, the note."""
    rows = []
    over = ((cmp.get("verdicts") or {}).get("min_effect") or {})
    for raw, s in zip(cmp.get("claims") or [], declared_claims(cmp)):
        unit = metric_or_blank(s["metric"]).unit
        src = ("the claim's min_effect" if raw.get("min_effect") is not None else
               "compare.verdicts.min_effect" if s["metric"] in over else "the metric's margin")
        b = "every generator but the references (`*`)" if s["b"] == EVERY else s["b"]
        rows.append([f"`{s['id']}`", claim_track(s), s["claim"], s["a"], b, f"`{s['metric']}`", s["direction"],
                     f"{s['margin']:g} {unit} ({src})", s["paper_value"], s["note"]])
    return _md(rows, ["id", "track", "claim", "a", "b", "metric", "direction", "margin", "paper", "note"])


def margins_markdown(cmp: dict) -> str:
    """The margins of the metrics the claims, sanity checks and exploratory pairs use: metric, margin, unit, why
    (the metric table's sentence), and whether ``compare.verdicts.min_effect`` overrides it."""
    from .measures.metric_table import METRICS

    over = ((cmp.get("verdicts") or {}).get("min_effect") or {})
    rows = []
    for m in METRICS:
        if m.margin is None and m.name not in over:
            continue
        value = margin(m.name, cmp.get("verdicts"))
        note = f" (compare.verdicts.min_effect; the table says {m.margin:g})" if m.name in over else ""
        rows.append([f"`{m.name}`", f"{value:g}{note}", m.unit, m.margin_why])
    return _md(rows, ["metric", "margin", "unit", "why that size"])


def page_parts(cmp: dict) -> dict:
    """``{marker: Markdown}`` of docs/compare/verdicts.md: the words (:data:`animsynth.verdicts.WORDS`), the
    declared claims and the margins."""
    from ..verdicts import words_markdown

    return {"verdict-words": words_markdown(), "declared-claims": claims_markdown(cmp),
            "margins": margins_markdown(cmp)}


def update_page(text: str, parts: dict) -> str:
    """``text`` with the content between ``<!-- name -->`` and ``<!-- /name -->`` replaced by ``parts[name]`` for
    each name (ValueError naming a marker that is missing)."""
    for name, body in parts.items():
        pat = re.compile(rf"(<!-- {re.escape(name)} -->\n).*?(\n<!-- /{re.escape(name)} -->)", re.S)
        if not pat.search(text):
            raise ValueError(f"no <!-- {name} --> ... <!-- /{name} --> markers in the page")
        text = pat.sub(lambda mt: mt.group(1) + body + mt.group(2), text)
    return text


def _main() -> None:  # pragma: no cover - the command that rewrites the page; the test checks its result
    """Rewrite docs/compare/verdicts.md from config/config.yaml (validated by config/schema.yaml)."""
    from pathlib import Path

    import yaml

    from ..config import validate_config

    root = Path(__file__).resolve().parents[3]
    cfg = yaml.safe_load((root / "config" / "config.yaml").read_text(encoding="utf-8"))
    validate_config(cfg, str(root / "config" / "schema.yaml"))
    page = root / "docs" / "compare" / "verdicts.md"
    page.write_text(update_page(page.read_text(encoding="utf-8"), page_parts(cfg["compare"])), encoding="utf-8")
    print(f"wrote {page}")


if __name__ == "__main__":  # pragma: no cover
    _main()
