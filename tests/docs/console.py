"""The ``console`` blocks of the documentation: their commands, and what they print.

A ``console`` block holds commands (lines starting with ``$ ``) each followed by the output
it prints. A command may end with a shell comment ``# exit N`` giving its exit code
(default 0). ``figures.Workspace`` runs them. Each shown output line must agree with a line
of the real output (trailing spaces aside), in the same order; a shown line ending in
``...`` must be the beginning of one; a line ``...`` stands for output that is left out.
Numbers agree within one unit of the last digit the documentation prints
(``figures.agree``); the words around them exactly.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

from tests.docs import figures

REPO = figures.REPO
BLOCK = re.compile(r"^```console\n(.*?)^```", re.M | re.S)
EXIT = re.compile(r"#\s*exit\s+(\d+)\s*$")


@dataclass(frozen=True)
class Command:
    """One documented command, its exit code and the output lines shown for it."""

    line: str
    argv: tuple[str, ...]
    exit_code: int
    shown: tuple[str, ...]


def commands(text: str) -> list[Command]:
    """The commands of every ``console`` block of a Markdown text, in order."""
    found: list[Command] = []
    for block in BLOCK.findall(text):
        current: tuple[str, list[str]] | None = None
        for raw in block.splitlines():
            if raw.startswith("$ "):
                if current is not None:
                    found.append(_command(*current))
                current = (raw[2:], [])
            elif current is not None:
                current[1].append(raw.rstrip())
        if current is not None:
            found.append(_command(*current))
    return found


def _command(line: str, shown: list[str]) -> Command:
    match = EXIT.search(line)
    argv = tuple(shlex.split(line, comments=True))
    return Command(line, argv, int(match.group(1)) if match else 0, tuple(shown))


def mismatch(shown: tuple[str, ...], output: str) -> str | None:
    """Why ``output`` does not show ``shown`` in order, or None when it does."""
    lines = [line.rstrip() for line in output.splitlines()]
    at = 0
    for expected in shown:
        if expected in ("...", ""):
            continue
        while at < len(lines) and figures.agree_line(expected, lines[at]) is not None:
            at += 1
        if at == len(lines):
            return f"line not printed (in this order): {expected!r}"
        at += 1
    return None


def refreshed(shown: tuple[str, ...], output: str) -> tuple[list[str], list[str]]:
    """``shown`` with each line replaced by the printed line of the same words, in order
    (its figures as printed now), and the shown lines no printed line has the words of.

    Of the printed lines with the same words, a shown line stands for the one whose figures
    are nearest: fewest integers (a joint, a count) that differ, then fewest other numbers
    out of tolerance, then the first."""
    lines = [line.rstrip() for line in output.splitlines()]
    fresh: list[str] = []
    lost: list[str] = []
    at = 0
    for expected in shown:
        if expected in ("...", ""):
            fresh.append(expected)
            continue
        candidates = [
            (figures.distance(expected, lines[i]), i, new)
            for i in range(at, len(lines))
            if (new := figures.restate(expected, lines[i])) is not None
        ]
        if not candidates:
            lost.append(expected)
            fresh.append(expected)
            continue
        _, i, new = min(candidates)
        fresh.append(new)
        at = i + 1
    return fresh, lost


def workspace(tmp: Path) -> Path:
    """A folder where the documented relative paths (cases/, robots/) resolve."""
    for name in ("cases", "robots"):
        (tmp / name).symlink_to(REPO / name, target_is_directory=True)
    return tmp
