"""`trackplan export` on a planned run."""

from __future__ import annotations

import csv
import json
import os
import stat
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.export import TrajectoryTable, read_trajectory_table
from trackplan.io.results import read_trajectory_csv
from trackplan.writers import (
    WRITERS,
    Writer,
    export,
    export_trajectory,
    register_writer,
    writer_for_file,
    writer_named,
)


def test_export_ros_csv_json_and_bad_format(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["plan", str(CASES / "paper-line.yaml"), "--out", str(run), "--no-report"]) == 0
    assert main(["export", str(run), "--format", "ros", "--joint-names", "a,b,c,d,e,f"]) == 0
    message = yaml.safe_load((run / "trajectory.ros.yaml").read_text())
    assert message["joint_names"] == ["a", "b", "c", "d", "e", "f"]
    point = message["points"][-1]
    assert set(point) == {"positions", "velocities", "accelerations", "effort", "time_from_start"}
    assert len(point["positions"]) == 6
    assert main(["export", str(run), "--format", "json"]) == 0
    assert (run / "trajectory.json").is_file()
    other = tmp_path / "elsewhere.csv"
    assert main(["export", str(run), "--format", "csv", "--output", str(other)]) == 0
    assert other.read_text().startswith("t,")
    assert main(["export", str(run), "--format", "xml"]) == 2
    assert "unknown export format" in capsys.readouterr().err


def _planned(tmp_path: Path) -> Path:
    run = tmp_path / "run"
    assert main(["plan", str(CASES / "paper-line.yaml"), "--out", str(run), "--no-report"]) == 0
    return run


@pytest.mark.parametrize("name", ["trajectory.csv", "result.json", "history.csv"])
def test_export_refuses_to_overwrite_the_runs_own_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    run = _planned(tmp_path)
    (run / "history.csv").write_text("generation\n")
    before = {file.name: file.read_bytes() for file in run.iterdir()}
    for fmt in ("csv", "json"):
        for output in (run / name, run / "." / name, tmp_path / "run" / ".." / "run" / name):
            capsys.readouterr()
            assert main(["export", str(run), "--format", fmt, "--output", str(output)]) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and err.startswith("output: ")
            assert name in err and "run's own" in err
    assert {file.name: file.read_bytes() for file in run.iterdir()} == before
    # the CSV given as the source is protected too
    csv = run / "trajectory.csv"
    assert main(["export", str(csv), "--format", "csv", "--output", str(csv)]) == 2
    assert csv.read_bytes() == before["trajectory.csv"]


def test_export_refuses_an_output_that_is_no_regular_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the temporary file was renamed over it: as root, --output /dev/full became a file
    run = _planned(tmp_path)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    assert main(["export", str(run), "--format", "ros", "--output", str(fifo)]) == 2
    err = capsys.readouterr().err
    assert err == f"output: {str(fifo)!r} is not a regular file; give a file name\n"
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_csv_export_quotes_names_and_neutralises_formulas(tmp_path: Path) -> None:
    run = _planned(tmp_path)
    names = ['=HYPERLINK("http://x")', "a\nb", 'c"d,e', "+1", "-2", "@SUM(A1)"]
    out = export_trajectory(run, "csv", tmp_path / "names.csv", joint_names=names)
    with out.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["t", *("'" + name if name[0] in "=+-@" else name for name in names)]
    assert rows[0][2] == "a\nb" and rows[0][3] == 'c"d,e'
    table = np.array(rows[1:], dtype=float)  # every other cell is a plain number
    written = np.loadtxt(run / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2)
    assert table.shape == (len(written), 7)
    np.testing.assert_array_equal(table, written[:, :7])  # exact: shortest round trip


@pytest.mark.parametrize("fmt", ["csv", "json", "ros"])
def test_exported_files_respect_the_umask(tmp_path: Path, fmt: str) -> None:
    run = _planned(tmp_path)
    previous = os.umask(0o027)
    try:
        written = export_trajectory(run, fmt, tmp_path / f"out.{fmt}")
    finally:
        os.umask(previous)
    assert stat.S_IMODE(written.stat().st_mode) == 0o640
    assert stat.S_IMODE((run / "trajectory.csv").stat().st_mode) == 0o666 & ~previous


def test_trajectory_files_with_a_byte_order_mark_are_read(tmp_path: Path) -> None:
    run = _planned(tmp_path)
    csv_file = tmp_path / "bom.csv"
    csv_file.write_bytes(b"\xef\xbb\xbf" + (run / "trajectory.csv").read_bytes())
    t, q = read_trajectory_csv(csv_file, 6)
    table = read_trajectory_table(csv_file)
    written = np.loadtxt(run / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2)
    np.testing.assert_array_equal(t, written[:, 0])
    np.testing.assert_array_equal(q, written[:, 1:7])
    np.testing.assert_array_equal(table.q, written[:, 1:7])


@pytest.fixture
def writers() -> Iterator[dict[str, Writer]]:
    """The registry, restored after the test."""
    before = dict(WRITERS)
    yield WRITERS
    WRITERS.clear()
    WRITERS.update(before)


def test_the_writers_are_registered_by_name_and_suffix() -> None:
    assert list(WRITERS) == ["csv", "json", "ros"]
    for writer in WRITERS.values():
        assert isinstance(writer, Writer) and writer.default_file.endswith(writer.suffix)
    assert writer_named("ROS") is WRITERS["ros"]
    assert writer_for_file(Path("a/b.Json")) is WRITERS["json"]
    assert writer_for_file(Path("motion.ros.yaml")) is WRITERS["ros"]
    with pytest.raises(CaseError, match=r"unknown export format 'xml': use one of csv, json, ros"):
        writer_named("xml")
    with pytest.raises(CaseError, match=r"no export format for 'a.txt'.*\.csv \(csv\)"):
        writer_for_file(Path("a.txt"))


def test_export_picks_the_writer_by_the_output_suffix(tmp_path: Path) -> None:
    run = _planned(tmp_path)
    message = yaml.safe_load(export(run, tmp_path / "motion.yaml").read_text())
    assert list(message) == ["header", "joint_names", "points"]
    content = json.loads(export(run, tmp_path / "motion.json").read_text())
    assert content["units"]["positions"] == "rad"
    assert export(run, tmp_path / "motion.csv").read_text().startswith("t,")
    with pytest.raises(CaseError, match="no export format: give one of csv, json, ros") as error:
        export(run)
    assert error.value.key == "format"
    with pytest.raises(CaseError, match=r"no export format for 'motion\.txt'"):
        export(run, tmp_path / "motion.txt")
    assert not (tmp_path / "motion.txt").exists()


@dataclass(frozen=True)
class _LinesWriter:
    """A format that is no built-in one: a comment, then ``t q1 ... qn`` per sample."""

    name: str = "lines"
    suffix: str = ".lines"
    default_file: str = "trajectory.lines"

    def write(self, table: TrajectoryTable, output: Path, **options: Any) -> None:
        rows = np.column_stack([table.t, table.q]).tolist()
        body = "\n".join(" ".join(map(repr, row)) for row in rows)
        output.write_text(f"# {options.get('comment', '')}\n{body}\n")


def test_a_registered_writer_serves_export_and_the_cli(
    tmp_path: Path, writers: dict[str, Writer], capsys: pytest.CaptureFixture[str]
) -> None:
    run = _planned(tmp_path)
    register_writer(_LinesWriter())
    written = export(run, tmp_path / "out.lines", comment="hello")
    lines = written.read_text().splitlines()
    assert lines[0] == "# hello"
    expected = np.loadtxt(run / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2)[:, :7]
    np.testing.assert_array_equal(np.loadtxt(lines[1:]), expected)  # repr round-trips exactly
    capsys.readouterr()
    assert main(["export", str(run), "--format", "lines"]) == 0
    assert capsys.readouterr().out == f"wrote {run / 'trajectory.lines'}\n"
    assert (run / "trajectory.lines").read_text().splitlines()[1:] == lines[1:]


def test_a_writer_name_or_suffix_is_registered_once(writers: dict[str, Writer]) -> None:
    with pytest.raises(ValueError, match="a writer named 'csv' is registered already"):
        register_writer(_LinesWriter(name="csv"))
    with pytest.raises(ValueError, match=r"the suffix '\.json' belongs to the 'json' writer"):
        register_writer(_LinesWriter(suffix=".json", default_file="t.json"))
    with pytest.raises(ValueError, match="does not end with"):
        register_writer(_LinesWriter(default_file="trajectory.txt"))
    assert list(WRITERS) == ["csv", "json", "ros"]
