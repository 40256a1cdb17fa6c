"""Points files: the compiled parser and the line-by-line reader agree; large files load."""

from __future__ import annotations

import contextlib
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from tests.large_paths import helix_points, write_helix_case, write_points_csv
from trackplan.errors import CaseError
from trackplan.io import points_file
from trackplan.io.points_file import load_points_csv
from trackplan.io.sizes import MAX_POINTS_BYTES

WELL_FORMED = {
    "header": "x,y,z\n0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "no header": "0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3",
    "comments and blanks first": "# seam 4\n\n  \nx, y, z\n0.1,0,0\n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "CRLF and spaces": "x,y,z\r\n 0.1 , 0 , 0\r\n0.2,0.1,0\r\n0.3,0.1,1e-3\r\n",
    "a comment among the rows": "0.1,0,0\n# half way\n0.2,0.1,0\n0.3,0.1,1e-3\n# end",
    "an empty line among the rows": "0.1,0,0\n\n0.2,0.1,0\r\n\r\n0.3,0.1,1e-3\n",
}

READ_LINE_BY_LINE = {
    "a blank line among the rows": "0.1,0,0\n   \n0.2,0.1,0\n0.3,0.1,1e-3\n",
    "an indented comment among the rows": "0.1,0,0\n  # half way\n0.2,0.1,0\n0.3,0.1,1e-3\n",
}

EXPECTED = np.array([[0.1, 0.0, 0.0], [0.2, 0.1, 0.0], [0.3, 0.1, 1e-3]])


@pytest.mark.parametrize("text", [*WELL_FORMED.values(), *READ_LINE_BY_LINE.values()])
def test_both_readers_give_the_same_points(tmp_path, monkeypatch, text):
    csv = tmp_path / "seam.csv"
    csv.write_text(text)
    fast = load_points_csv(csv)
    monkeypatch.setattr(points_file, "_parse_fast", lambda *_: None)
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


# --------------------------------------------------------------------------- hostile files


def _load_in_thread(file: Path, timeout: float = 10.0) -> BaseException | None:
    """Load ``file`` in a daemon thread; the exception raised, or fail when it takes over
    ``timeout`` s (a FIFO without a writer blocks ``open`` forever)."""
    outcome: list[BaseException | None] = []

    def load() -> None:
        try:
            load_points_csv(file)
            outcome.append(None)
        except BaseException as exc:  # handed to the test
            outcome.append(exc)

    thread = threading.Thread(target=load, daemon=True)
    thread.start()
    thread.join(timeout)
    assert outcome, f"loading {file} did not end within {timeout} s"
    return outcome[0]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path: Path) -> None:
    fifo = tmp_path / "seam.csv"
    os.mkfifo(fifo)
    try:
        error = _load_in_thread(fifo, timeout=5.0)
    finally:  # release a reader that blocked (before the fix)
        with contextlib.suppress(OSError):
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
    assert isinstance(error, CaseError)
    assert "is not a regular file (a FIFO)" in str(error) and str(fifo) in str(error)


def test_a_device_is_refused_without_reading_it() -> None:
    error = _load_in_thread(Path("/dev/null"))
    assert isinstance(error, CaseError)
    assert "is not a regular file (a character device)" in str(error)


def test_a_directory_is_refused(tmp_path: Path) -> None:
    error = _load_in_thread(tmp_path)
    assert isinstance(error, CaseError) and "is a directory" in str(error)


def test_a_file_over_the_byte_limit_is_refused_before_it_is_read(tmp_path: Path) -> None:
    big = tmp_path / "seam.csv"
    with big.open("wb") as handle:  # sparse: no disk, and nothing to read quickly
        handle.truncate(MAX_POINTS_BYTES + 1)
    start = time.perf_counter()
    with pytest.raises(CaseError) as caught:
        load_points_csv(big, "case.yaml", "path.segments[0].points.file")
    assert time.perf_counter() - start < 1.0
    assert caught.value.file == str(big)
    assert f"{MAX_POINTS_BYTES + 1} bytes, more than the {MAX_POINTS_BYTES}" in caught.value.message


def test_a_file_over_the_row_limit_is_refused_before_it_is_parsed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(points_file, "MAX_POINTS_ROWS", 10)
    np.testing.assert_array_equal(load_points_csv(_rows(tmp_path, 10)), helix_points(10))
    csv = write_points_csv(tmp_path / "seam.csv", helix_points(10))  # header + 10 rows
    monkeypatch.setattr(points_file, "_parse_fast", _never)
    with pytest.raises(CaseError, match="11 lines, more than the 10 a points file may have"):
        load_points_csv(csv)


def _never(_: str) -> None:
    raise AssertionError("parsed a file over the limit")


def _rows(folder: Path, n: int) -> Path:
    """A points file of ``n`` rows without a header: at the limit when ``n`` is."""
    file = folder / "ok.csv"
    np.savetxt(file, helix_points(n), delimiter=",", fmt="%.17g")
    return file


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        ("0.1,0,0\n0.3_1,0.1,0\n0.3,0.1,0\n", 2, "'0.3_1'"),
        ("0.1,0,0\n\uff10.2,0.1,0\n0.3,0.1,0\n", 2, "'\uff10.2'"),
        ("0.1,0,0\n0.2,0.1,0\n0x1p-3,0.1,0\n", 3, "'0x1p-3'"),
        ("0.1,0,0\n0.2,0.1,0\ninfinity,0.1,0\n", 3, "'infinity'"),
        ("0.1;0;0\n0.2;0.1;0\n", 1, "';'"),
        ("x,y,z\n0.1\t0\t0\n0.2\t0.1\t0\n", 2, "a tab"),
        ("0.1,0,0\n0.2,0.1,0\n0.3;0.1;0\n", 3, "';'"),
    ],
)
def test_numbers_are_strict_and_other_separators_are_named(
    tmp_path: Path, text: str, line: int, what: str
) -> None:
    csv = tmp_path / "seam.csv"
    csv.write_text(text, encoding="utf-8")
    with pytest.raises(CaseError) as caught:
        load_points_csv(csv)
    assert caught.value.key == f"line {line}" and what in caught.value.message


def test_only_the_first_row_may_be_a_header(tmp_path: Path) -> None:
    csv = tmp_path / "seam.csv"
    csv.write_text("x,y,z\nseam,four,mm\n0.1,0,0\n0.2,0.1,0\n", encoding="utf-8")
    with pytest.raises(CaseError) as caught:
        load_points_csv(csv)
    assert caught.value.key == "line 2" and "seam,four,mm" in caught.value.message


@pytest.mark.parametrize("text", [*WELL_FORMED.values(), *READ_LINE_BY_LINE.values()])
def test_a_byte_order_mark_is_accepted_with_or_without_a_header(tmp_path: Path, text: str) -> None:
    csv = tmp_path / "seam.csv"
    csv.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    np.testing.assert_array_equal(load_points_csv(csv), EXPECTED)


def test_a_name_too_long_for_the_system_is_one_line(tmp_path: Path) -> None:
    name = tmp_path / ("x" * 5000)
    with pytest.raises(CaseError) as caught:
        load_points_csv(name, "case.yaml", "path.segments[0].points.file")
    assert caught.value.file == "case.yaml" and caught.value.key == "path.segments[0].points.file"
    assert "file name too long" in caught.value.message and len(caught.value.message) < 300


def test_old_mac_line_ends_are_line_ends(tmp_path: Path) -> None:
    csv = tmp_path / "seam.csv"
    csv.write_bytes(b"x,y,z\r0.1,0,0\r0.2,0.1,0\r0.3,0.1,1e-3\r")
    np.testing.assert_array_equal(load_points_csv(csv), EXPECTED)
    csv.write_bytes(b"x,y,z\r0.1,0,0\r0.2,zero,0\r")
    with pytest.raises(CaseError, match="line 3"):
        load_points_csv(csv)


def test_the_screened_search_finds_the_row_the_line_by_line_reader_names(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from tests.fuzzing import ROOT, mutate_points

    rng = np.random.default_rng(11)
    shipped = (ROOT / "cases" / "bead.csv").read_text()
    csv = tmp_path / "seam.csv"
    n_bad = 0
    special = [
        "x,y,z\n0,0,0\n" + "9" * 400 + ",0,0\n",
        "  x,y,z\n0,0,0\n1,1,1\n",
        "0,0,0\n\x0c\n1,1,1\n2,2,x\n",
        "0,0,0\n1,\u00a01,1\n1,2,;\n",
        "x,y,z\nx,y,z\n0,0,0\n",
        "\n\n  \n# only\n",
        "0,0,0\n1,1,1e99\n2,2,1e100\n",
    ]
    for k in range(200 + len(special)):
        text = special[k - 200] if k >= 200 else mutate_points(shipped, rng)
        csv.write_text(text, encoding="utf-8")
        outcomes = []
        for screened in (True, False):
            if not screened:
                monkeypatch.setattr(points_file, "_first_bad_row", lambda *_: None)
            try:
                outcomes.append(load_points_csv(csv).tolist())
            except CaseError as exc:
                outcomes.append(exc.one_line())
        monkeypatch.undo()
        assert outcomes[0] == outcomes[1], text
        n_bad += isinstance(outcomes[0], str) and " line " in outcomes[0]
    assert n_bad > 50  # the mutants do break rows
