"""Points files: the compiled parser and the line-by-line reader agree; large files load."""

from __future__ import annotations

import numpy as np
import pytest

from tests.large_paths import helix_points, write_helix_case, write_points_csv
from trackplan.errors import CaseError
from trackplan.io import points_file
from trackplan.io.points_file import load_points_csv

WELL_FORMED = {
    "header": "x,y,z\n0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "no header": "0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3",
    "comments and blanks first": "# seam 4\n\n  \nx, y, z\n0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "CRLF and spaces": "x,y,z\r\n 0.1 , 0 , 0\r\n0.2,0.1,0\r\n0.3,0.1,1e-3\r\n",
}

READ_LINE_BY_LINE = {
    "a comment among the rows": "0.1,0,0\n# half way\n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "a blank line among the rows": "0.1,0,0\n   \n0.2,0.1,0\n0.3,0.1,1e-3\n",
}

EXPECTED = np.array([[0.1, 0.0, 0.0], [0.2, 0.1, 0.0], [0.3, 0.1, 1e-3]])


@pytest.mark.parametrize("text", [*WELL_FORMED.values(), *READ_LINE_BY_LINE.values()])
def test_both_readers_give_the_same_points(tmp_path, monkeypatch, text):
    csv = tmp_path / "seam.csv"
    csv.write_text(text)
    fast = load_points_csv(csv)
    monkeypatch.setattr(points_file, "_parse_fast", lambda _: None)
    np.testing.assert_array_equal(fast, EXPECTED)
    np.testing.assert_array_equal(load_points_csv(csv), EXPECTED)


@pytest.mark.parametrize("text", WELL_FORMED.values())
def test_well_formed_files_take_the_compiled_parser(text):
    np.testing.assert_array_equal(points_file._parse_fast(text), EXPECTED)


@pytest.mark.parametrize(
    ("text", "line"),
    [
        ("x,y,z\n0.1,0,0\n0.2,nan,0\n", 3),
        ("0.1,0,0\n0.2,0.1\n0.3,0,0\n", 2),
        ("0.1,0,0\n0.2,0.1,0,4\n", 2),
        ("0.1,0,0\n0.2,0.1,0 # note\n", 2),
        ("0.1,0,0\n0.2,0.1,1e999\n", 2),
    ],
)
def test_a_bad_row_is_named_by_its_line(tmp_path, text, line):
    csv = tmp_path / "seam.csv"
    csv.write_text(text)
    with pytest.raises(CaseError, match=f"line {line}"):
        load_points_csv(csv)


@pytest.mark.slow
def test_a_million_point_file_loads_exactly(tmp_path):
    points = helix_points(1_000_000)
    loaded = load_points_csv(write_points_csv(tmp_path / "helix.csv", points))
    np.testing.assert_array_equal(loaded, points)


def test_the_helix_case_names_its_points_file(tmp_path):
    case = write_helix_case(tmp_path, 50)
    assert "helix-50.csv" in case.read_text()
    np.testing.assert_array_equal(load_points_csv(tmp_path / "helix-50.csv"), helix_points(50))
