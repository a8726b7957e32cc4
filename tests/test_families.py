"""The family registry: one list of families that the report, the scoreboard and the scale harness read."""

from __future__ import annotations

import importlib
import inspect

import pytest
import yaml

from animsynth import families, report, scale, scoreboard
from animsynth.config import validate_config

from conftest import REPO


def test_names_letters_and_report_places_are_unique():
    fams = families.FAMILIES
    for attr in ("name", "letter", "number", "section"):
        values = [getattr(f, attr) for f in fams]
        assert len(set(values)) == len(values), attr
    assert [f.number for f in families.report_order()] == sorted(f.number for f in fams)
    with pytest.raises(ValueError, match="unknown family 'nope'"):
        families.get("nope")
    with pytest.raises(ValueError, match="data must be one of"):
        families.Family("x", "p", "s", "X", "x", "video", 9)


def test_the_report_and_the_scoreboard_read_the_registry():
    order = [f.name for f in families.report_order()]
    assert list(scoreboard.ROW_ORDER) == order
    for table in (report.FAMILY_PAPERS, report.FAMILY_SHORT, report.FAMILY_LETTER, report.FAMILY_SECTION):
        assert list(table) == order
    assert report.claim_ids(["compare", "simplicial", "compare"]) == ["C1", "S1", "C2"]


def _scale_cfg() -> dict:
    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    cfg.update(yaml.safe_load((REPO / "config" / "scale.yaml").read_text()))
    validate_config(cfg, str(REPO / "config" / "schema.yaml"))
    return cfg["scale"]


@pytest.mark.parametrize("family", scale.FAMILIES)
def test_each_scaled_familys_point_calls_its_steps_with_arguments_they_take(family):
    cfg = _scale_cfg()
    target, kwargs = scale.point_kwargs(family, cfg, 100, 7, resolution="0.5", mirror=None)
    module, name = scale.STEP_FUNCTIONS[target]
    steps = getattr(importlib.import_module(module), name)
    inspect.signature(steps).bind(scale.Steps, **kwargs)  # raises TypeError on a keyword the steps do not take
    assert kwargs["n"] == 100 and kwargs["seed"] == 7
    for kw, key in families.get(family).scale.kwargs.items():
        value = cfg
        for part in key.split("."):
            value = value[part]
        assert kwargs[kw] == value


def test_scale_points_of_other_families_are_refused():
    with pytest.raises(ValueError, match="does not measure family 'compare'"):
        scale.point_kwargs("compare", _scale_cfg(), 100, 0)


def _dotted_names() -> list[str]:
    """Every ``module:function`` and dotted ``animsynth.`` name written in the family registry's source."""
    import re

    text = inspect.getsource(families)
    return sorted(set(re.findall(r"animsynth(?:\.\w+)+(?::\w+)?", text)))


@pytest.mark.parametrize("dotted", _dotted_names())
def test_every_dotted_name_of_the_registry_is_where_it_says(dotted):
    """A ``module:function`` names the module the function is defined in (not one that re-exports it); a dotted
    module or ``module.attribute`` resolves."""
    if ":" in dotted:
        module, name = dotted.split(":")
        fn = getattr(importlib.import_module(module), name)
        assert fn.__module__ == module, f"{dotted}: {name} lives in {fn.__module__}"
        return
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return
    pytest.fail(f"{dotted} does not resolve")


def test_the_registry_names_dotted_names_at_all():
    assert any(":" in d for d in _dotted_names())
