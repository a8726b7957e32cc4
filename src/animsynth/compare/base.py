"""The common interface of the compare family's generators, re-exported from :mod:`animsynth.generator`
(where it lives so the method families can build their generators on it): :class:`Generator`
(``fit`` / ``generate``), the :class:`Database` of clips they are fitted on, and the root helpers."""

from __future__ import annotations

from ..generator import Database, Generator, align_root, check_generated

__all__ = ["Database", "Generator", "align_root", "check_generated"]
