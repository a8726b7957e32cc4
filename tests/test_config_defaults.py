"""Defaults live in config/schema.yaml; config/config.yaml repeats them only as documentation.

Every value config.yaml sets for a key the schema gives a default must be that default, or be a demo
size: a value that a real-data config (cmu.yaml, samba.yaml, paper.yaml) sets back to the schema's
default, or whose line in config.yaml says "demo" and names the schema default as the full size (keys
of the synthetic character, which the real-data runs do not use). So the files cannot drift apart.
"""

from __future__ import annotations

import re

import yaml

from conftest import REPO

CONFIG = REPO / "config"
REAL_DATA = ("cmu.yaml", "samba.yaml", "paper.yaml")


def _leaves(cfg: dict, schema: dict, path=()):
    """(key path, value in cfg, schema default) for every key of cfg whose schema node has a default."""
    props = schema.get("properties", {})
    for key, value in cfg.items():
        node = props.get(key)
        if node is None:
            continue
        if isinstance(value, dict) and "properties" in node:
            yield from _leaves(value, node, path + (key,))
        elif "default" in node:
            yield path + (key,), value, node["default"]


def _get(cfg: dict, path):
    for key in path:
        if not isinstance(cfg, dict) or key not in cfg:
            return None, False
        cfg = cfg[key]
    return cfg, True


def _demo_comment(text: str, key: str, schema_default) -> bool:
    """config.yaml's line for ``key`` is commented as a demo size whose full size is the schema default."""
    full = yaml.safe_dump(schema_default, default_flow_style=True).strip().removesuffix("...").strip()
    for line in re.findall(rf"(?m)^\s*{re.escape(key)}:.*#.*$", text):
        comment = line.split("#", 1)[1]
        if "demo" in comment and full.replace(" ", "") in comment.replace(" ", ""):
            return True
    return False


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return float(a) == float(b)
    return a == b


def test_config_yaml_repeats_the_schema_defaults_or_names_a_demo_size():
    schema = yaml.safe_load((CONFIG / "schema.yaml").read_text())
    default = yaml.safe_load((CONFIG / "config.yaml").read_text())
    real = [yaml.safe_load((CONFIG / name).read_text()) or {} for name in REAL_DATA]
    text = (CONFIG / "config.yaml").read_text()
    drift, checked = [], 0
    for path, value, schema_default in _leaves(default, schema):
        checked += 1
        if _same(value, schema_default):
            continue
        restored = [_same(v, schema_default) for v, found in (_get(r, path) for r in real) if found]
        if not any(restored) and not _demo_comment(text, path[-1], schema_default):
            drift.append(f"{'.'.join(path)}: config.yaml {value!r}, schema default {schema_default!r}")
    assert checked > 150, checked  # the walk reaches the families' nested keys
    assert not drift, "config.yaml differs from the schema without a real-data config restoring it:\n" + \
        "\n".join(drift)
