"""Configuration checks that a JSON Schema cannot express, and seed derivation."""

from __future__ import annotations

import hashlib


class ConfigError(ValueError):
    """A configuration value is wrong; the message names the key."""


def derive_seed(master: int, *names) -> int:
    """A 32-bit seed from the master seed and a path of names.

    Stable across runs, machines and Python versions (no ``hash()``), so a
    changed seed of one experiment reruns only that experiment's jobs.
    """
    text = "/".join([str(int(master))] + [str(n) for n in names])
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "little")


def check_config(config: dict) -> None:
    """Cross-key checks on a schema-validated config; raise :class:`ConfigError`."""
    ids = [t["id"] for t in config["trials"]]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ConfigError(f"config key 'trials': duplicate id(s) {dup}")
    known = set(ids)
    src = config["mocap_source"]
    for k, t in enumerate(config["trials"]):
        where = f"config key 'trials[{k}]' (id {t['id']!r})"
        if src == "synthetic":
            if "frames" not in t:
                raise ConfigError(f"{where}: synthetic trials need 'frames'")
            if t["kind"] not in ("walk_straight", "walk_turn", "run_straight", "run_turn", "dance"):
                raise ConfigError(f"{where}: the synthetic generator cannot make kind {t['kind']!r}")
        else:
            has_amc = "amc" in t and "asf" in t
            if not has_amc and "bvh" not in t:
                raise ConfigError(f"{where}: mocap_source {src!r} needs 'amc' and 'asf', or 'bvh'")
            if src == "cmu" and "sha256" not in t:
                raise ConfigError(f"{where}: CMU trials need 'sha256' (LF-normalised) so downloads are verified")
    if src == "user" and not config.get("data_dir"):
        raise ConfigError("config key 'data_dir': mocap_source 'user' needs the folder holding your files")
    subsets = {k: v for k, v in config["subsets"].items() if v}
    if not subsets:
        raise ConfigError("config key 'subsets': at least one subset is needed")
    for name, members in subsets.items():
        bad = [m for m in members if m not in known]
        if bad:
            raise ConfigError(f"config key 'subsets.{name}': unknown trial id(s) {bad}")
    for name, tid in config["resequencing_trials"].items():
        if tid not in known:
            raise ConfigError(f"config key 'resequencing_trials.{name}': unknown trial id {tid!r}")
