"""The ``resequencing`` config block: cross-key checks (beyond the JSON Schema, which holds the defaults) and the
adapters that turn its keys and the workflow's wildcards into the methods' arguments.

The config is read here once: :func:`method_params` turns the block into :class:`MethodParams` (sign mode,
translation scale, Lee weights, ST-Isomap block), which the workflow steps (:mod:`.jobs`) pass to the methods;
nothing here reads a step's results.

Imported when the workflow is parsed (:func:`check`): nothing here loads the numeric modules at import time.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..config import ConfigError

__all__ = ["METHODS", "METRICS", "GDOF", "METHOD_LABEL", "METRIC_LABEL", "check", "left_out", "gdof_flag", "gdof_name",
           "sign_mode_of", "st_parameters", "lee_kwargs", "MethodParams", "method_params"]

#: The methods and metrics of the study, the global-DOF wildcard values and the figures' labels.
METHODS = ("isomap", "stisomap")
METRICS = ("l2", "lee")
GDOF = {"noglobal": False, "global": True}
METHOD_LABEL = {"isomap": "Isomap", "stisomap": "ST-Isomap"}
METRIC_LABEL = {"l2": "L2", "lee": "Lee"}


def check(config: dict) -> None:
    """Raise :class:`ConfigError` naming the key for ``resequencing`` values the schema cannot check.

    ``config``: the whole workflow config, validated by ``config/schema.yaml`` (defaults filled in).
    """
    rs, trials = config["resequencing"], config["resequencing_trials"]
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


def left_out(config: dict) -> list[str]:
    """The re-sequencing clips of this run (``resequencing_trials``) that ``resequencing.datasets`` leaves out of
    the study, one line each naming the key (the workflow prints them at parse time on a user's data)."""
    rs = config["resequencing"]
    return [f"resequencing: clip {d!r} ({t}) of resequencing_trials left out by resequencing.datasets: "
            f"[{', '.join(rs['datasets'])}] (add {d} to resequencing.datasets)"
            for d, t in config["resequencing_trials"].items() if d not in rs["datasets"]]


def st_parameters(st: dict, fps: float) -> dict:
    """Keyword arguments of ST-Isomap (:func:`~animsynth.resequencing.embedding.spatio_temporal_distances`,
    :func:`~animsynth.resequencing.sparse_st.st_neighbours`; counts in frames) from the ``stisomap`` config block
    (durations in seconds) at ``fps`` frames per second.

    ``ctn_min_gap`` is at least ``temporal_window`` and ``ctn_reach`` at least one frame.
    """
    tw = int(st["temporal_window"])
    return {
        "temporal_window": tw,
        "c_atn": float(st["c_atn"]),
        "c_ctn": float(st["c_ctn"]),
        "ctn_neighbors": int(st["ctn_neighbors"]),
        "ctn_min_gap": max(tw, int(round(float(st["ctn_min_gap_s"]) * fps))),
        "ctn_tolerance": int(st["ctn_tolerance"]),
        "ctn_reach": max(1, int(round(float(st["ctn_reach_s"]) * fps))),
    }


def gdof_flag(name: str) -> bool:
    """The global-DOF flag of a wildcard value (``noglobal``, ``global``)."""
    try:
        return GDOF[name]
    except KeyError:
        raise ValueError(f"global-DOF wildcard must be one of {sorted(GDOF)}, got {name!r}") from None


def gdof_name(flag: bool) -> str:
    """The wildcard value of a global-DOF flag (inverse of :func:`gdof_flag`)."""
    return "global" if flag else "noglobal"


def sign_mode_of(cfg: dict) -> str:
    """The L2 features' quaternion sign mode (``linearisation.sign_mode``), checked against
    :data:`~animsynth.resequencing.features.SIGN_MODES`."""
    from .features import SIGN_MODES  # here: the config checks stay free of the numeric modules

    mode = cfg["linearisation"]["sign_mode"]
    if mode not in SIGN_MODES:
        raise ValueError(f"config key 'resequencing.linearisation.sign_mode': {mode!r} is not one of {SIGN_MODES}")
    return mode


def lee_kwargs(lee: dict) -> dict:
    """Keyword arguments of :func:`~animsynth.resequencing.distances.lee_distances` from the ``lee`` block."""
    return {"weights": lee["weights"], "nu": float(lee["nu"]), "sqrt": bool(lee["sqrt"])}


@dataclass(frozen=True)
class MethodParams:
    """The methods' arguments from the ``resequencing`` block, read once (:func:`method_params`).

    Attributes
    ----------
    sign_mode : str
        The L2 features' quaternion sign mode (``linearisation.sign_mode``, checked).
    translation_scale : float
        Weight of the root translation in the L2 features (``linearisation.translation_scale``).
    lee : dict
        Keyword arguments of the Lee distances (:func:`lee_kwargs`).
    stisomap : dict
        The ``stisomap`` block (durations in seconds; :meth:`st` gives frames).
    """

    sign_mode: str
    translation_scale: float
    lee: dict
    stisomap: dict

    def st(self, fps: float) -> dict:
        """ST-Isomap's keyword arguments at ``fps`` frames per second (:func:`st_parameters`)."""
        return st_parameters(self.stisomap, fps)


def method_params(cfg: dict) -> MethodParams:
    """:class:`MethodParams` of the ``resequencing`` block ``cfg`` (validated by the schema, defaults filled in)."""
    return MethodParams(sign_mode=sign_mode_of(cfg), translation_scale=float(cfg["linearisation"]["translation_scale"]),
                        lee=lee_kwargs(cfg["lee"]), stisomap=dict(cfg["stisomap"]))
