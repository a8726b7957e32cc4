"""The one reader of the papers' published tables (``../shared/papers/*.csv`` by default).

Config names every table ``published.<family>.<table>`` (a path; relative paths are resolved
against the workflow's own directory, so ``snakemake --directory elsewhere`` still finds them).
The workflow declares each existing table as an input of the jobs that read it, so a changed
published file reruns exactly those jobs.

Behaviour, the same for every family:

* ``path`` is ``None`` or the file does not exist: :func:`read_table` returns ``None`` and logs a
  WARNING naming the path; the tables then leave their ``paper_*`` columns empty.
* the file exists but is malformed (a required column missing, a non-number in a numeric column,
  no rows): :class:`PublishedError` naming the file and the line.

Families map the returned table to their own names (each family's ``settings.py`` or ``jobs.py``);
they never open the file themselves.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from pathlib import Path

import pandas as pd

__all__ = ["PublishedError", "read_table", "resolve"]

log = logging.getLogger("animsynth.published")


class PublishedError(ValueError):
    """A published table that exists but cannot be read as declared."""


def resolve(path, base) -> Path | None:
    """``path`` as given in config -> an absolute path (relative ones against ``base``); None stays None."""
    if path in (None, ""):
        return None
    p = Path(path)
    return p if p.is_absolute() else (Path(base) / p).resolve()


def read_table(path, columns: Iterable[str], numeric: Iterable[str] = (), *, what: str = "published table",
               config_key: str | None = None) -> pd.DataFrame | None:
    """Read one published table.

    Parameters
    ----------
    path : path or None
        The CSV file. ``None``, '' or a missing file -> ``None`` (and a WARNING naming the path).
    columns : iterable of str
        Columns the table must have (others are kept).
    numeric : iterable of str
        Columns that must parse as numbers (empty cells allowed, read as NaN).
    what : str
        What the table is, for messages ("Gauch & Peters Table II").
    config_key : str, optional
        The config key that names the file, for messages.

    Returns
    -------
    table : DataFrame or None
        The table as read (numeric columns as float), or None when there is no file.

    Raises
    ------
    PublishedError
        The file exists but lacks a column, has a non-number in a numeric column (the message names
        the line, header = line 1), or has no rows.
    """
    key = f" (config key '{config_key}')" if config_key else ""
    if path in (None, "") or not Path(path).is_file():
        log.warning("%s not found at %s%s: the paper_* values stay empty", what, path, key)
        return None
    p = Path(path)
    try:
        df = pd.read_csv(p, dtype=str, keep_default_na=False)
    except pd.errors.EmptyDataError:
        raise PublishedError(f"{p}: empty file ({what}{key})") from None
    except pd.errors.ParserError as e:
        raise PublishedError(f"{p}: not a CSV table ({what}{key}): {e}") from None
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise PublishedError(f"{p}, line 1: {what}{key} lacks column(s) {missing}; has {list(df.columns)}")
    if df.empty:
        raise PublishedError(f"{p}: {what}{key} has no rows")
    for c in numeric:
        if c not in df.columns:
            raise PublishedError(f"{p}, line 1: {what}{key} lacks numeric column {c!r}")
        s = df[c].str.strip()
        num = pd.to_numeric(s.where(s != ""), errors="coerce")
        bad = num.isna() & (s != "")
        if bad.any():
            i = int(bad.to_numpy().nonzero()[0][0])
            raise PublishedError(f"{p}, line {i + 2}: column {c!r} holds {s.iloc[i]!r}, not a number ({what}{key})")
        df[c] = num.astype(float)
    log.info("read %s from %s (%d rows)", what, p, len(df))
    return df
