"""Cross-key checks of the ``resequencing`` config block (beyond the JSON Schema)."""

from __future__ import annotations

from ..config import ConfigError

__all__ = ["check_resequencing_config"]


def check_resequencing_config(rs: dict, trials: dict) -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check.

    ``rs``: the ``resequencing`` block; ``trials``: the ``resequencing_trials`` mapping.
    """
    for ds in rs["datasets"]:
        if ds not in trials:
            raise ConfigError(f"config key 'resequencing.datasets': {ds!r} is not a key of 'resequencing_trials' "
                              f"({sorted(trials)})")
    for key in ("datasets", "methods", "metrics", "global_dof"):
        vals = list(rs[key])
        if len(set(vals)) != len(vals):
            raise ConfigError(f"config key 'resequencing.{key}': duplicate entries {vals}")
    steps = [int(s) for s in rs["explanations"]["frame_steps"]]
    if int(rs["frame_step"]) not in steps:
        raise ConfigError(f"config key 'resequencing.explanations.frame_steps' {steps} must include "
                          f"resequencing.frame_step ({rs['frame_step']}): Table 2 is read from those rows")
    if rs["linearisation"]["sign_mode"] not in rs["explanations"]["sign_modes"]:
        raise ConfigError(f"config key 'resequencing.explanations.sign_modes' {rs['explanations']['sign_modes']} "
                          f"must include resequencing.linearisation.sign_mode ({rs['linearisation']['sign_mode']!r})")
