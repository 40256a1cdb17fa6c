"""``trackplan part``: a part's faces and edges as tables, JSON and part.html."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import main

PIPE = str(CASES / "parts" / "pipe-plate.step")


def test_part_lists_faces_and_edges(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["part", PIPE]) == 0
    out = capsys.readouterr().out
    assert "faces of" in out and "exact B-rep" in out
    assert out.count("cylinder") == 2 and out.count("circle (closed)") == 4
    assert "0.0600 0.0000 0.0000" in out  # the foot circle's start, m


def test_part_json_lists_the_same_in_metres(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["part", PIPE, "--json"]) == 0
    listing = json.loads(capsys.readouterr().out)
    assert listing["exact"] is True and listing["source"] == PIPE
    assert [f["id"] for f in listing["faces"]] == list(range(1, 11))
    assert [e["id"] for e in listing["edges"]] == list(range(1, 19))
    top = next(f for f in listing["faces"] if f["kind"] == "plane" and f["area"] > 0.07)
    assert np.allclose(top["normal"], [0, 0, 1]) and top["axis"] is None
    pipe = next(f for f in listing["faces"] if f["kind"] == "cylinder" and f["area"] > 0.055)
    assert np.isclose(pipe["area"], 2 * np.pi * 0.06 * 0.15) and pipe["normal"] is None
    (foot,) = [e for e in listing["edges"] if sorted(e["faces"]) == sorted([top["id"], pipe["id"]])]
    assert foot["kind"] == "circle" and np.isclose(foot["length"], 2 * np.pi * 0.06)
    assert (top["id"], pipe["id"], foot["id"]) == (3, 7, 10)  # as docs/cad.md names them
    assert np.allclose(foot["start"], [0.06, 0, 0]) and np.allclose(foot["end"], foot["start"])


def test_part_out_writes_part_html_with_the_ids_on_hover(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["part", PIPE, "--json", "--out", str(tmp_path / "view")]) == 0
    captured = capsys.readouterr()
    json.loads(captured.out)  # the JSON stays clean: the written file is said on stderr
    page = (tmp_path / "view" / "part.html").read_text()
    assert "wrote" in captured.err and "part.html" in captured.err
    assert "Plotly.newPlot" in page and "mesh3d" in page
    for face in range(1, 11):
        assert f"face {face}: " in page
    for edge in range(1, 19):
        assert f"edge {edge}: " in page


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("part.iges", "", "a part file is STEP or a mesh"),
        ("part.step", "not a step file\n", "cannot read it as STEP"),
        ("missing.step", None, "no such STEP file"),
    ],
    ids=["suffix", "unreadable", "missing"],
)
def test_bad_part_files_are_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, text: str | None, message: str
) -> None:
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    assert main(["part", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and message in captured.err
    assert captured.err.startswith(str(path))


def test_an_empty_out_is_refused_before_reading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["part", PIPE, "--out", ""]) == 2
    assert capsys.readouterr().err.startswith("--out: an empty name is not a folder")
    assert list(tmp_path.iterdir()) == []
