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
from trackplan.io.export import read_trajectory_table
from trackplan.io.results import read_trajectory_csv
from trackplan.writers import (
    WRITERS,
    ExportSource,
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
    message = _load_yaml((run / "trajectory.ros.yaml").read_text())
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


def _load_yaml(text: str) -> Any:
    """YAML read safely by libyaml's C loader where PyYAML has it (ten times the pure-Python
    loader's speed on a trajectory's thousands of points)."""
    return yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


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
    assert list(WRITERS)[:3] == ["csv", "json", "ros"]  # then the program writers
    for writer in WRITERS.values():
        assert isinstance(writer, Writer)
        assert writer.folder or writer.default_file.endswith(writer.suffix)
    assert writer_named("ROS") is WRITERS["ros"]
    assert writer_for_file(Path("a/b.Json")) is WRITERS["json"]
    assert writer_for_file(Path("motion.ros.yaml")) is WRITERS["ros"]
    with pytest.raises(CaseError, match=r"unknown export format 'xml': use one of csv, json, ros"):
        writer_named("xml")
    with pytest.raises(CaseError, match=r"no export format for 'a.txt'.*\.csv \(csv\)"):
        writer_for_file(Path("a.txt"))


def test_export_picks_the_writer_by_the_output_suffix(tmp_path: Path) -> None:
    run = _planned(tmp_path)
    message = _load_yaml(export(run, tmp_path / "motion.yaml").read_text())
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
    folder: bool = False

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        table = source.table
        rows = np.column_stack([table.t, table.q]).tolist()
        body = "\n".join(" ".join(map(repr, row)) for row in rows)
        (folder / options["file_name"]).write_text(f"# {options.get('comment', '')}\n{body}\n")
        return (options["file_name"],)


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
    before = list(WRITERS)
    with pytest.raises(ValueError, match="a writer named 'csv' is registered already"):
        register_writer(_LinesWriter(name="csv"))
    with pytest.raises(ValueError, match=r"the suffix '\.json' belongs to the 'json' writer"):
        register_writer(_LinesWriter(suffix=".json", default_file="t.json"))
    with pytest.raises(ValueError, match="does not end with"):
        register_writer(_LinesWriter(default_file="trajectory.txt"))
    assert list(WRITERS) == before


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One run of paper-line, shared: tests that write into it copy it first."""
    run = tmp_path_factory.mktemp("export") / "run"
    assert main(["plan", str(CASES / "paper-line.yaml"), "--out", str(run), "--no-report"]) == 0
    return run


def _copied(run: Path, tmp_path: Path) -> Path:
    import shutil

    return Path(shutil.copytree(run, tmp_path / "run"))


@dataclass(frozen=True)
class _FolderWriter:
    """A program format of two files: ``NAME.prog`` (the samples) and ``NAME.dat`` (the
    options it was given); with ``fail``, it raises after writing the first."""

    name: str = "twofiles"
    suffix: str = ".prog"
    default_file: str = "twofiles"
    folder: bool = True
    fail: bool = False
    names: tuple[str, ...] = ()

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        stem = options.get("name") or "main"
        main_file, data_file = self.names or (f"{stem}.prog", f"{stem}.dat")
        (folder / main_file).write_text(f"{len(source.table.t)} samples\n")
        if self.fail:
            raise CaseError("the robot cannot be driven by this format", key="robot")
        options.pop("file_name", None)
        (folder / data_file).write_text(json.dumps(options, sort_keys=True, default=str))
        return (main_file, data_file)


def _staging_left(*folders: Path) -> list[Path]:
    return [p for folder in folders if folder.exists() for p in folder.glob(".trackplan-*")]


def test_a_folder_writer_writes_its_files_into_a_folder(
    paper_run: Path, tmp_path: Path, writers: dict[str, Writer], capsys: pytest.CaptureFixture[str]
) -> None:
    run = _copied(paper_run, tmp_path)
    register_writer(_FolderWriter())
    main_file = export(run, format="twofiles", name="weld")
    assert main_file == run / "twofiles" / "weld.prog"
    assert main_file.read_text() == f"{len(read_trajectory_table(run).t)} samples\n"
    assert sorted(p.name for p in (run / "twofiles").iterdir()) == ["weld.dat", "weld.prog"]
    # --output names the folder (created with its parents); the CLI prints every file
    out = tmp_path / "cell" / "robot1"
    capsys.readouterr()
    assert main(["export", str(run), "--format", "twofiles", "--output", str(out)]) == 0
    assert capsys.readouterr().out == f"wrote {out / 'main.prog'}\nwrote {out / 'main.dat'}\n"
    assert _staging_left(run, out, out.parent) == []
    # a folder writer is picked by name only, never by a file's suffix
    with pytest.raises(CaseError, match=r"no export format for 'a\.prog'"):
        writer_for_file(Path("a.prog"))
    file = tmp_path / "taken"
    file.write_text("x")
    with pytest.raises(CaseError, match=r"'.*taken' is not a folder; give a folder"):
        export(run, file, format="twofiles")


def test_a_failing_writer_leaves_nothing_behind(
    paper_run: Path, tmp_path: Path, writers: dict[str, Writer]
) -> None:
    run = _copied(paper_run, tmp_path)
    before = sorted(p.name for p in run.iterdir())
    register_writer(_FolderWriter(fail=True))
    new = tmp_path / "new" / "folder"
    with pytest.raises(CaseError, match="cannot be driven"):
        export(run, new, format="twofiles")
    assert not (tmp_path / "new").exists()  # every folder it made is gone
    kept = tmp_path / "kept"
    kept.mkdir()
    (kept / "main.prog").write_text("the old program\n")
    with pytest.raises(CaseError, match="cannot be driven"):
        export(run, kept, format="twofiles")
    assert [p.name for p in kept.iterdir()] == ["main.prog"]
    assert (kept / "main.prog").read_text() == "the old program\n"
    with pytest.raises(CaseError, match="cannot be driven"):
        export(run, format="twofiles")
    assert sorted(p.name for p in run.iterdir()) == before


def test_a_writer_never_replaces_the_runs_files(
    paper_run: Path, tmp_path: Path, writers: dict[str, Writer]
) -> None:
    run = _copied(paper_run, tmp_path)
    before = {p.name: p.read_bytes() for p in run.iterdir()}
    register_writer(_FolderWriter(names=("weld.prog", "result.json")))
    with pytest.raises(CaseError, match=r"is the run's own result\.json"):
        export(run, run, format="twofiles")
    assert {p.name: p.read_bytes() for p in run.iterdir()} == before  # not even weld.prog
    WRITERS.pop("twofiles")
    register_writer(_FolderWriter(names=("../escape.prog", "a.dat")))
    with pytest.raises(ValueError, match=r"names '\.\./escape\.prog', not a file it wrote"):
        export(run, tmp_path / "out", format="twofiles")
    assert not (tmp_path / "escape.prog").exists() and not (tmp_path / "out").exists()


@dataclass(frozen=True)
class _ProgramWriter:
    """A program format of one file: the program the builder returns, and the options."""

    name: str = "prog"
    suffix: str = ".prog"
    default_file: str = "main.prog"
    folder: bool = False

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        keys = ("motion", "name", "period", "force")
        program = source.program(**{key: options[key] for key in keys if key in options})
        again = source.program(**{key: options[key] for key in keys if key in options})
        assert again is program  # built once per set of arguments
        text = json.dumps({"program": program, "max_points": options.get("max_points")})
        (folder / options["file_name"]).write_text(text)
        return (options["file_name"],)


@pytest.fixture
def fake_builder(monkeypatch: pytest.MonkeyPatch) -> list[dict[str, Any]]:
    """The export source's builder replaced by one that records its calls."""
    calls: list[dict[str, Any]] = []

    def build_program(replayed: Any, **arguments: Any) -> dict[str, Any]:
        calls.append({"replayed": replayed, **arguments})
        return {"case": replayed.case.name, **arguments}

    monkeypatch.setattr("trackplan.writers.source.build_program", build_program)
    return calls


def test_the_cli_options_reach_the_program_writer(
    paper_run: Path,
    tmp_path: Path,
    writers: dict[str, Writer],
    fake_builder: list[dict[str, Any]],
    capsys: pytest.CaptureFixture[str],
) -> None:
    register_writer(_ProgramWriter())
    out = tmp_path / "weld.prog"
    arguments = ["--motion", "joint", "--name", "Weld 1", "--period", "0.008"]
    argv = ["export", str(paper_run), "--format", "prog", "--output", str(out), *arguments]
    assert main([*argv, "--max-points", "500", "--force"]) == 0
    assert capsys.readouterr().out == f"wrote {out}\n"
    written = json.loads(out.read_text())
    assert written == {
        "program": {
            "case": "paper-line",
            "motion": "joint",
            "name": "Weld 1",
            "period": 0.008,
            "force": True,
        },
        "max_points": 500,
    }
    assert len(fake_builder) == 1
    replayed = fake_builder[0]["replayed"]
    assert replayed.folder == paper_run
    np.testing.assert_allclose(replayed.plan.trajectory.q, replayed.table.q, rtol=0, atol=1e-9)
    # defaults, and the case given with --case
    assert main(["export", str(paper_run), "--format", "prog", "--output", str(out), "--case",
                 str(CASES / "paper-line.yaml")]) == 0  # fmt: skip
    assert json.loads(out.read_text())["program"] == {
        "case": "paper-line", "motion": "cartesian", "name": None, "period": None, "force": False
    }  # fmt: skip


def test_bad_program_options_are_one_line(
    paper_run: Path, tmp_path: Path, writers: dict[str, Writer], capsys: pytest.CaptureFixture[str]
) -> None:
    register_writer(_ProgramWriter())
    out = str(tmp_path / "x.prog")
    for extra, message in (
        (["--motion", "circular"], "--motion: unknown motion 'circular': use cartesian or joint"),
        (["--max-points", "1"], "--max-points: must be at least 2 points, got 1"),
    ):
        capsys.readouterr()
        assert main(["export", str(paper_run), "--format", "prog", "--output", out, *extra]) == 2
        err = capsys.readouterr().err
        assert err == message + "\n"
    # a number that does not parse is a usage error, as for every typed option
    assert main(["export", str(paper_run), "--format", "prog", "--period", "soon"]) == 2
    assert "Invalid value for '--period'" in capsys.readouterr().err
    assert not Path(out).exists()


def test_a_program_needs_a_run(
    paper_run: Path, tmp_path: Path, writers: dict[str, Writer], fake_builder: list[dict[str, Any]]
) -> None:
    register_writer(_ProgramWriter())
    table = read_trajectory_table(paper_run)
    source = ExportSource(table=table)
    with pytest.raises(CaseError, match=r"a program needs a run folder.*held in memory"):
        export(source, tmp_path / "a.prog", format="prog")
    bare = tmp_path / "motion.csv"
    bare.write_bytes((paper_run / "trajectory.csv").read_bytes())
    with pytest.raises(CaseError, match="a program needs a run folder"):
        export(bare, format="prog")
    assert not (tmp_path / "main.prog").exists() and fake_builder == []


def test_the_format_help_lists_every_registered_writer(
    writers: dict[str, Writer], capsys: pytest.CaptureFixture[str]
) -> None:
    register_writer(_FolderWriter())
    assert main(["export", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.replace("│", " ").split())  # the help's box wraps
    assert "One of csv, json, ros, krl, rapid, fanuc, urscript, twofiles." in out


@dataclass(frozen=True)
class _PartsWriter:
    """A program split into parts: ``main.prog`` and ``part1.prog`` … ``partN.prog``."""

    name: str = "parts"
    suffix: str = ".part"
    default_file: str = "parts"
    folder: bool = True
    parts: int = 5

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        names = ("main.prog", *(f"part{k}.prog" for k in range(1, self.parts + 1)))
        for name in names:
            (folder / name).write_text(name)
        return names


@pytest.mark.parametrize("parts", [3, 5])
def test_the_cli_sums_up_a_program_of_many_parts(
    paper_run: Path,
    tmp_path: Path,
    writers: dict[str, Writer],
    capsys: pytest.CaptureFixture[str],
    parts: int,
) -> None:
    register_writer(_PartsWriter(parts=parts))
    out = tmp_path / "prog"
    capsys.readouterr()
    assert main(["export", str(paper_run), "--format", "parts", "--output", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    files = ["main.prog", *(f"part{k}.prog" for k in range(1, parts + 1))]
    assert sorted(p.name for p in out.iterdir()) == sorted(files)
    if parts == 3:
        assert printed == [f"wrote {out / name}" for name in files]
    else:
        assert printed == [
            f"wrote {out / 'main.prog'}",
            f"wrote {out / 'part1.prog'}",
            f"wrote 4 more files in {out}{os.sep} (part2.prog … part5.prog)",
        ]


def test_the_source_builds_the_runs_program_once(paper_run: Path) -> None:
    source = ExportSource.of(paper_run)
    program = source.program(motion="joint", name="line")
    assert source.program(motion="joint", name="line") is program  # cached
    assert program.motion == "joint" and program.n_dof == 6
    assert source.program() is not program and source.program().motion == "cartesian"
    assert source.run is source.run  # replayed once
    assert source.run.folder == paper_run
