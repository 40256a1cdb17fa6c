"""An empty ``--out`` (or ``--output``) is refused on every command that has one."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import CASES
from trackplan.cli import main

CASE = str(CASES / "paper-line.yaml")

COMMANDS = [
    ["plan", CASE, "--no-report"],
    ["optimize", CASE, "--no-report"],
    ["demo"],
    ["map", CASE, "--rpy", "0", "0", "0", "--z", "0", "--points", "3"],
    ["batch", "study.yaml"],
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda command: command[0])
@pytest.mark.parametrize("spelling", ["separate", "equals"])
def test_an_empty_out_is_refused_before_any_work(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    command: list[str],
    spelling: str,
) -> None:
    # Path("") is Path("."): plan --out "" wrote its run into the current folder
    monkeypatch.chdir(tmp_path)
    out = ["--out", ""] if spelling == "separate" else ["--out="]
    assert main([*command, *out]) == 2
    err = capsys.readouterr().err
    assert err == (
        "--out: an empty name is not a folder; give the output folder, e.g. --out runs/x\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_an_empty_export_output_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    run = tmp_path / "run"
    assert main(["plan", CASE, "--out", str(run), "--no-report"]) == 0
    monkeypatch.chdir(run)
    before = sorted(path.name for path in run.iterdir())
    capsys.readouterr()
    assert main(["export", str(run), "--format", "json", "--output", ""]) == 2
    assert capsys.readouterr().err.startswith("--output: an empty name is not a file")
    assert sorted(path.name for path in run.iterdir()) == before


def test_an_out_value_that_merely_looks_empty_is_a_folder_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # "--out" as the value of another option is not the option itself
    monkeypatch.chdir(tmp_path)
    code = main(["plan", CASE, "--no-report", "--timing", "--out", "--out", str(tmp_path / "r")])
    assert code == 2 and "--timing" in capsys.readouterr().err
