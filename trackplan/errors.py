"""Exceptions of trackplan.

One root exception. Input problems raise :class:`CaseError`, which carries the file
and the key path so the CLI can print one line and exit with code 2. Expected
outcomes (unreachable, limit violated, infeasible) are results, never exceptions.
"""

from __future__ import annotations


class TrackplanError(Exception):
    """Root of every exception raised on purpose by trackplan."""


class CaseError(TrackplanError):
    """Bad input: a case file, robot file, trajectory file or argument.

    Parameters
    ----------
    message
        What is wrong and what is expected ("must be > 0, got -1").
    file
        The file the problem is in, if any.
    key
        The key path inside the file, e.g. ``path.segments[2].arc.normal``.
    """

    def __init__(self, message: str, file: str | None = None, key: str | None = None):
        self.message = message
        self.file = file
        self.key = key
        super().__init__(self.one_line())

    def one_line(self) -> str:
        """The error as one line: ``file: key: message``."""
        parts = [p for p in (self.file, self.key) if p]
        return ": ".join([*parts, self.message])
