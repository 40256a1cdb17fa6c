"""Seeded fuzzing of the shipped case and robot files (the fast subset; the benchmark runs more)."""

from __future__ import annotations

from pathlib import Path

from tests.fuzzing import fuzz


def test_mutants_never_crash_hang_or_give_vague_messages(tmp_path: Path) -> None:
    counts = fuzz(tmp_path, n_mutants=60, n_plans=4, seed=1)
    assert counts.runs >= 60
    assert counts.internal_errors == []
    assert counts.tracebacks == 0
    assert counts.warnings == []
    assert counts.hangs == 0
    assert counts.bad_messages == []
    assert counts.exit_codes.get(2, 0) > 20  # the mutants do break the files
