"""Cost curves: CPU time, wall time and peak memory of each family's main steps vs size.

Each measurement (one family at one size) runs in a **fresh child process**
(``multiprocessing`` with the ``spawn`` start method, so the child shares no
memory with the parent). Inside it every step is timed with
``time.process_time`` (CPU seconds of all the process's threads, BLAS included)
and ``time.perf_counter`` (wall), and its peak memory is the child's peak
resident set size *during that step*: before the step the kernel's high-water
mark is reset (``echo 5 > /proc/self/clear_refs``) and after it ``VmHWM`` is
read from ``/proc/self/status``. That peak includes everything resident in the
child at the time (the interpreter and libraries, ~100-150 MB, and data of
earlier steps still held). Where the reset is not possible the value is
``getrusage(RUSAGE_SELF).ru_maxrss`` of the child, the peak since it started
(column ``peak_kind`` says which).

Each family owns the steps it measures (``scale_steps`` in its workflow-step or cost module, named by its
:class:`animsynth.families.ScaleStudy` in the family registry, with the config keys they read); this module only
measures them:

* simplicial: one fold (PCA, Delaunay complex, motion graph, vector field and a
  1,000-step generated path) on synthetic walking trials totalling ``n`` training frames.
* resequencing: neighbours, exact minimum k, embedding and one Dijkstra path on a
  database of ``n`` frames (synthetic, or a CMU mirror); also the landmark-vs-exact check.
* facegraph: pre-processing, then sample-graph creation and merging with both
  threshold searches on ``n`` synthetic CK+-layout sequences.
* meshdetail: the hybrid (GP detail) model trained on ``n`` frames of the
  synthetic skirt character at a given mesh resolution (vertices recorded in ``vertices``).
"""

from __future__ import annotations

import logging
import resource
import time
from contextlib import contextmanager

import numpy as np
import pandas as pd

from . import families as _families

log = logging.getLogger("animsynth.scale")

COLUMNS = ["family", "step", "n", "cpu_s", "wall_s", "peak_mb"]
#: the families the scale study measures (the registry's :func:`animsynth.families.scaled`)
FAMILIES = tuple(f.name for f in _families.scaled())


# ----------------------------------------------------------------------------- measuring


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _peak_mb(reset_ok: bool) -> float:
    if reset_ok:
        try:
            with open("/proc/self/status") as f:
                for line in f:
                    if line.startswith("VmHWM:"):
                        return int(line.split()[1]) / 1024.0
        except OSError:
            pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux


class Steps:
    """Collects one row per timed step (use :meth:`step` as a context manager)."""

    def __init__(self, family: str, n: int, **extra):
        self.family, self.n, self.extra, self.rows = family, int(n), extra, []

    @contextmanager
    def step(self, name: str, **info):
        ok = _reset_peak()
        c0, w0 = time.process_time(), time.perf_counter()
        yield info
        c1, w1 = time.process_time(), time.perf_counter()
        self.rows.append({"family": self.family, "step": name, "n": self.n, "cpu_s": c1 - c0, "wall_s": w1 - w0,
                          "peak_mb": _peak_mb(ok), "peak_kind": "step VmHWM" if ok else "process ru_maxrss",
                          **self.extra, **info})


#: measurement -> (module, function): each family owns its measured steps (a function
#: ``scale_steps(recorder, n, **kwargs)`` that times its steps with ``recorder(family, n, **extra)``,
#: a :class:`Steps`), named in the family registry; this module only measures.
STEP_FUNCTIONS = {f"{f.name}_steps": tuple(f.scale.steps.split(":")) for f in _families.scaled()}


def _step_function(target: str):
    import importlib

    module, name = STEP_FUNCTIONS[target]
    return getattr(importlib.import_module(module), name)


def point_kwargs(family: str, cfg: dict, n: int, seed: int, resolution: float | None = None,
                 mirror: str | None = None) -> tuple[str, dict]:
    """The measurement (a key of :data:`STEP_FUNCTIONS`) and its keyword arguments for one point of a cost curve.

    Parameters
    ----------
    family : a family the scale study measures (:data:`FAMILIES`)
    cfg : the ``scale`` config block; the family's :class:`animsynth.families.ScaleStudy` names the keys read
    n, seed : the size and the point's seed
    resolution : the mesh resolution of the point (families measured over resolutions only)
    mirror : the CMU mirror (``scale.source: cmu``; families that read it only)
    """
    study = _families.get(family).scale
    if study is None:
        raise ValueError(f"the scale study does not measure family {family!r}; it measures {list(FAMILIES)}")
    kwargs = {"n": int(n), "seed": int(seed)}
    for kw, key in study.kwargs.items():
        value = cfg
        for part in key.split("."):
            value = value[part]
        kwargs[kw] = value
    if study.resolutions:
        kwargs["resolution"] = float(resolution)
    if study.mirror:
        kwargs[study.mirror] = mirror
    return f"{family}_steps", kwargs


def _child_main():
    """Entry point of the measuring process: JSON ``{"target", "kwargs"}`` on stdin, rows as JSON on stdout."""
    import json
    import sys

    from threadpoolctl import threadpool_limits

    req = json.loads(sys.stdin.read())
    kwargs = req["kwargs"]
    with threadpool_limits(limits=int(kwargs.pop("blas_threads", 1)), user_api="blas"):
        rows = _step_function(req["target"])(Steps, **kwargs)
    sys.stdout.write("\n" + json.dumps(rows, default=float) + "\n")


def measure(target: str, timeout: float | None = None, **kwargs) -> list[dict]:
    """Run ``target(**kwargs)`` (a step function of this module) in a fresh Python process; its rows.

    The child is a new interpreter (``subprocess``), so it shares no memory with
    the caller and its peak memory is its own.
    """
    import json
    import subprocess
    import sys

    if target not in STEP_FUNCTIONS:
        raise ValueError(f"unknown measurement {target!r}; one of {sorted(STEP_FUNCTIONS)}")
    cmd = [sys.executable, "-c", "from animsynth.scale import _child_main; _child_main()"]
    res = subprocess.run(cmd, input=json.dumps({"target": target, "kwargs": kwargs}), capture_output=True,
                         text=True, timeout=timeout)
    if res.returncode != 0:
        raise RuntimeError(f"{target}{kwargs} failed in the measuring process (exit code {res.returncode}; "
                           f"-9 = killed, e.g. out of memory):\n{res.stderr[-4000:]}")
    for line in res.stderr.splitlines():
        log.info("[%s] %s", target, line)
    return json.loads(res.stdout.strip().splitlines()[-1])


# ----------------------------------------------------------------------------- curves


def fit_exponent(n, t) -> float:
    """Least-squares slope of log(t) on log(n) (NaN with fewer than two positive points)."""
    n = np.asarray(n, float)
    t = np.asarray(t, float)
    ok = (n > 0) & (t > 0) & np.isfinite(t)
    if ok.sum() < 2 or np.unique(n[ok]).size < 2:
        return float("nan")
    return float(np.polyfit(np.log(n[ok]), np.log(t[ok]), 1)[0])


def exponents(curves: pd.DataFrame) -> pd.DataFrame:
    """Fitted exponent of CPU time and of peak memory per family x step (x resolution, metric, method,
    embedding method); NaN where a curve has fewer than two sizes."""
    # embedding_method: the re-sequencing embedding switches from exact to landmark at a size;
    # one exponent across the switch would describe neither
    keys = [c for c in ("family", "step", "resolution", "metric", "method", "embedding_method") if c in curves.columns]
    rows = []
    for key, g in curves.groupby(keys, dropna=False, sort=False):
        key = key if isinstance(key, tuple) else (key,)
        rows.append({**dict(zip(keys, key)), "sizes": int(g["n"].nunique()), "n_min": int(g["n"].min()),
                     "n_max": int(g["n"].max()), "cpu_exponent": round(fit_exponent(g["n"], g["cpu_s"]), 3),
                     "peak_mb_exponent": round(fit_exponent(g["n"], g["peak_mb"]), 3)})
    return pd.DataFrame(rows)


def plot_curves(curves: pd.DataFrame, path) -> None:
    """Log-log CPU seconds vs size, one panel per family, one line per step, exponent in the legend."""
    import matplotlib.pyplot as plt

    fams = [f for f in FAMILIES if f in set(curves["family"])]
    fig, axes = plt.subplots(1, max(1, len(fams)), figsize=(4.2 * max(1, len(fams)), 3.6), squeeze=False)
    for ax, fam in zip(axes[0], fams):
        g = curves[curves["family"] == fam]
        keys = [c for c in ("step", "resolution", "metric", "method", "embedding_method")
                if c in g.columns and g[c].notna().any()]
        for key, h in g.groupby(keys, dropna=False, sort=False):
            key = key if isinstance(key, tuple) else (key,)
            h = h.sort_values("n")
            e = fit_exponent(h["n"], h["cpu_s"])
            label = " ".join(str(k) for k in key if str(k) != "nan") + f" (n^{e:.2f})"
            ax.loglog(h["n"], h["cpu_s"], "o-", label=label)
        ax.set_title(fam)
        ax.set_xlabel(_families.get(fam).scale.axis)
        ax.set_ylabel("CPU s")
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
