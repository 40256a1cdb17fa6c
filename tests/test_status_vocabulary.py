"""One outcome vocabulary: no module of trackplan compares against a status word.

Outcomes are :class:`trackplan.status.Status` members, compared with ``is``; the words
(``"feasible"``, ``"failed"``, …) appear only where they are written to or read from files.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from trackplan.status import Status

PACKAGE = Path(__file__).resolve().parents[1] / "trackplan"
WORDS = frozenset(status.value for status in Status)


def _words(node: ast.expr) -> list[str]:
    """The status words a compared expression spells: a str constant, or a tuple, list or
    set of them (``x in ("failed", "interrupted")``)."""
    if isinstance(node, ast.Constant):
        return [node.value] if isinstance(node.value, str) and node.value in WORDS else []
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [word for element in node.elts for word in _words(element)]
    return []


def status_word_comparisons(source: str) -> list[tuple[int, str]]:
    """Every comparison (or ``match`` case) against a status word in ``source``.

    Returns
    -------
    list
        (line, the comparison's source) pairs, in the order of :func:`ast.walk`.
    """
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            if any(_words(side) for side in (node.left, *node.comparators)):
                found.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.MatchValue) and _words(node.value):
            found.append((node.lineno, f"case {ast.unparse(node.value)}"))
    return found


@pytest.mark.parametrize(
    "source",
    [
        'ok = result.status == "feasible"',
        'if "failed" != row.status: pass',
        'if row.status in ("failed", "interrupted"): pass',
        'if row.status not in {"collision"}: pass',
        'bad = result.status.value in ["unreachable", "x"]',
        'match row.status:\n    case "limits_violated":\n        pass',
    ],
)
def test_the_scan_finds_a_comparison_against_a_status_word(source: str) -> None:
    assert len(status_word_comparisons(source)) == 1


@pytest.mark.parametrize(
    "source",
    [
        "ok = result.status is Status.FEASIBLE",
        'word = Status.FAILED.value\nrow = {"status": "failed"}',
        "if row.status in (Status.FAILED, Status.INTERRUPTED): pass",
        'if mode == "free": pass',  # not a status word
        'message = "interrupted"',
    ],
)
def test_the_scan_leaves_enum_comparisons_and_written_words(source: str) -> None:
    assert status_word_comparisons(source) == []


def test_no_module_compares_against_a_status_word() -> None:
    found = [
        f"{file.relative_to(PACKAGE.parent)}:{line}: {text}"
        for file in sorted(PACKAGE.rglob("*.py"))
        for line, text in status_word_comparisons(file.read_text(encoding="utf-8"))
    ]
    assert not found, "compare with Status members, not their words:\n" + "\n".join(found)


def test_status_values_are_the_words_files_hold() -> None:
    """Members may be added at the end; the words already written to files never change."""
    words = [status.value for status in Status]
    assert words[:9] == [
        "feasible",
        "limits_violated",
        "unreachable",
        "branch_switch",
        "position_limits",
        "collision",
        "not_converged",
        "interrupted",
        "failed",
    ]
    assert [status.success for status in Status] == [True] + [False] * (len(words) - 1)
