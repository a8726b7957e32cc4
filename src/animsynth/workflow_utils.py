"""Small helpers for workflow scripts (kept here so scripts stay thin)."""

from __future__ import annotations

import logging
import os
import sys


def limit_compiled_threads(n: int) -> None:
    """Let numba's parallel loops use at most ``n`` threads (the rule's ``threads:``),
    so two single-thread jobs on a 2-core machine do not each start two threads."""
    n = max(1, int(n))
    numba = sys.modules.get("numba")
    if numba is None:
        os.environ["NUMBA_NUM_THREADS"] = str(n)  # read when numba is imported later
    else:
        # not the environment variable: numba rereads it at every compile and refuses a change
        # once its thread pool runs; set_num_threads only masks threads of the running pool
        numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))


def setup_logging(snakemake=None, name: str = "animsynth", log_path: str | None = None) -> logging.Logger:
    """Send ``animsynth`` log records (INFO and up) to the rule's ``log:`` file,
    and warnings also to stderr (the console of the run).

    Uncaught exceptions are logged too, so the log explains a failed job.
    Figures of the job are drawn with matplotlib's non-interactive Agg backend.
    Temporaries that an interrupted earlier run left for this job's outputs
    are removed (:func:`animsynth.atomic.clean_stale_temporaries`).
    """
    # workflow jobs draw figures into files: matplotlib's non-interactive backend for them only (the library
    # itself forces no backend, so interactive use keeps the user's)
    os.environ.setdefault("MPLBACKEND", "Agg")
    if "matplotlib" in sys.modules:
        sys.modules["matplotlib"].use("Agg")
    if log_path is None and snakemake is not None and len(snakemake.log):
        log_path = str(snakemake.log[0])
    root = logging.getLogger("animsynth")
    root.setLevel(logging.INFO)
    for h in list(root.handlers):
        root.removeHandler(h)
    if log_path:
        os.makedirs(os.path.dirname(os.path.abspath(log_path)), exist_ok=True)
        handler: logging.Handler = logging.FileHandler(log_path, mode="w")
    else:
        handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root.addHandler(handler)
    if log_path:
        # warnings (an implausible skeleton height, a fallback taken) also reach the console, not only the log
        console = logging.StreamHandler(sys.stderr)
        console.addFilter(lambda record: record.levelno == logging.WARNING)  # a failure's traceback is printed anyway
        console.setFormatter(logging.Formatter("animsynth: %(levelname)s: %(message)s"))
        root.addHandler(console)
    logger = logging.getLogger(name if name.startswith("animsynth") else f"animsynth.{name}")
    if snakemake is not None:
        from .atomic import clean_stale_temporaries

        clean_stale_temporaries(str(o) for o in snakemake.output)
        limit_compiled_threads(int(getattr(snakemake, "threads", 1) or 1))

    def _hook(exc_type, exc, tb):
        root.error("job failed", exc_info=(exc_type, exc, tb))
        sys.__excepthook__(exc_type, exc, tb)

    sys.excepthook = _hook
    return logger


class config_errors_stop_the_run:
    """Context manager for the workflow's config checks at parse time: a :class:`animsynth.config.ConfigError`
    prints its message once, ``animsynth: config error: ...`` (its own lines only: the key, what is wrong,
    what to do), and stops Snakemake with exit status 1, without the stack lines of the Snakefile and the
    library that Snakemake would print with it. Any other exception (a bug) keeps its traceback."""

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        from .config import ConfigError

        if kind is not None and issubclass(kind, ConfigError):
            print(f"animsynth: config error: {exc}", file=sys.stderr, flush=True)
            raise SystemExit(1)
        return False
