"""``trackplan report RUN [--png]``: the report rewritten from a run folder, the still images,
and the one look of every page (``report/page_style.py``)."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib import image

from tests.conftest import CASES, REPO
from tests.report.test_map_page import _map
from tests.study.test_study_report import ROWS, STUDY
from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.report.cell_figures import write_map_report
from trackplan.report.html import report_page
from trackplan.report.images import (
    CHROMIUM_ENV,
    IMAGES_DIR,
    VIEW_CLOSEST,
    VIEW_SIZE,
    VIEW_START,
    chromium,
    closest_frame,
    report_images,
)
from trackplan.report.page_style import FOOTER_CLASS, header, style_sheet
from trackplan.run_files import REPORT_FILE
from trackplan.study.report import write_study_report

LINE_CASE = CASES / "paper-line.yaml"
"""A one-seam case without a cell that plans in about half a second."""


@pytest.fixture(scope="module")
def line_run(tmp_path_factory) -> Path:
    """A run folder of the paper's line at its example placement, written without a report."""
    from trackplan.io.case_file import load_case
    from trackplan.outputs import write_run
    from trackplan.planning.plan import plan

    case = load_case(LINE_CASE)
    folder = tmp_path_factory.mktemp("line-run")
    write_run(folder, plan(case, case.bounds.example), case, report=False)
    return folder


def test_every_page_wears_the_one_style_header_and_footer(tmp_path, corner, corner_result):
    """report.html, map.html and the study's summary.html carry the same style sheet once,
    the same header (naming the page's kind) and footer, and no style of their own."""
    write_map_report(_map(), tmp_path)
    pages = {
        "report": report_page(corner_result, corner, [], ""),
        "placement map": (tmp_path / "map.html").read_text(encoding="utf-8"),
        "study": write_study_report(STUDY, ROWS, tmp_path).read_text(encoding="utf-8"),
    }
    for kind, page in pages.items():
        assert page.count("<style") == 1, kind
        assert page.count(style_sheet()) == 1, kind
        assert header(kind) in page, kind
        footer = f'<footer class="{FOOTER_CLASS}">'
        assert page.count(footer) == 1, kind
        assert page.index(header(kind)) < page.index("<h1>") < page.index(footer), kind


def test_no_module_but_page_style_holds_the_style_sheet():
    """One copy of the CSS: a table rule written anywhere else would be a second look."""
    holders = [
        path.relative_to(REPO).as_posix()
        for path in sorted((REPO / "trackplan").rglob("*.py"))
        if "border-collapse" in path.read_text(encoding="utf-8")
    ]
    assert holders == ["trackplan/report/page_style.py"]


def test_png_without_chromium_is_one_line_naming_make_browser(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv(CHROMIUM_ENV, raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))  # no chromium on it
    assert main(["report", str(tmp_path), "--png"]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "make browser" in err and "apt-get install chromium" in err


def test_a_chromium_named_in_the_environment_must_be_an_executable(tmp_path, monkeypatch):
    monkeypatch.setenv(CHROMIUM_ENV, str(tmp_path / "no-such-chromium"))
    with pytest.raises(CaseError, match="names no executable"):
        chromium()
    fake = tmp_path / "my-chromium"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.setenv(CHROMIUM_ENV, str(fake))
    assert chromium() == fake


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--out", "x"], "--out: names the images' folder: add --png"),
        ([], "no run folder here"),
    ],
)
def test_bad_report_arguments_are_one_line(tmp_path, capsys, args, words):
    assert main(["report", str(tmp_path / "missing"), *args]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err


@pytest.mark.slow  # about 4 s: the re-plan and three plots
def test_report_rewrites_report_html_and_plots_from_the_run_folder(line_run, capsys):
    assert not (line_run / REPORT_FILE).exists()  # written without a report
    assert main(["report", str(line_run)]) == ExitCode.OK
    page = (line_run / REPORT_FILE).read_text(encoding="utf-8")
    assert header("report") in page and "paper-line: feasible" in page
    assert 'id="robot-view"' in page
    for plot in ("joints.png", "path.png", "speed.png"):
        assert (line_run / plot).stat().st_size > 10_000, plot
    assert [p.name for p in line_run.iterdir() if p.name.startswith(".")] == []  # no staging
    assert f"wrote {line_run / REPORT_FILE}" in capsys.readouterr().out


def test_closest_frame_is_the_frame_nearest_the_closest_sample(corner_result):
    """Of 60 frames spread evenly (first and last sample included), the nearest to the
    sample the checker found closest; none without a cell or with no finite clearance."""
    assert corner_result.check.cell is None
    assert closest_frame(corner_result, 60) is None
    n = corner_result.trajectory.n_samples
    step = (n - 1) / 59  # samples between frames (about 26 here)
    cases = [(0, 0), (n - 1, 59), (round(30 * step), 30), (round(15.3 * step), 15)]
    cases += [(round(15.6 * step), 16)]  # past half-way to the next frame
    for point, frame in cases:
        cell = SimpleNamespace(min_clearance=0.02, point=point)
        result = replace(corner_result, check=replace(corner_result.check, cell=cell))
        assert closest_frame(result, 60) == frame, point
    cell = SimpleNamespace(min_clearance=np.inf, point=3)
    result = replace(corner_result, check=replace(corner_result.check, cell=cell))
    assert closest_frame(result, 60) is None


def _drawn_share(file: Path) -> float:
    """Share of the pixels that are not white."""
    pixels = image.imread(file)[..., :3]
    return float(np.mean((pixels < 0.98).any(axis=2)))


@pytest.mark.browser
@pytest.mark.slow
def test_report_images_draw_the_view_and_every_plot(line_run):
    """Without a cell: the view at the start and the plots, into ``images/`` by default,
    each file complete (moved into place from a staging folder that is gone)."""
    try:
        chromium()
    except CaseError as error:
        pytest.skip(f"BROWSER TEST SKIPPED: {error}")
    written = report_images(line_run)
    assert [p.name for p in written] == [VIEW_START, "joints.png", "path.png", "speed.png"]
    assert {p.parent for p in written} == {line_run / IMAGES_DIR}
    assert sorted(os.listdir(line_run / IMAGES_DIR)) == sorted(p.name for p in written)
    view = image.imread(written[0])
    assert view.shape[:2] == (VIEW_SIZE[1], VIEW_SIZE[0])
    assert _drawn_share(written[0]) > 0.05  # the robot, the axes and the legend were drawn


@pytest.mark.browser
@pytest.mark.slow
def test_a_cell_case_gets_the_view_at_its_closest_approach(tmp_path):
    """paper-corner-cell at cell.md's feasible placement: the view at the start and at the
    closest approach (titled with the distance), then the plots with clearance.png."""
    from tests.report.test_screenshots import CELL_PLACEMENT
    from trackplan.io.case_file import load_case
    from trackplan.outputs import write_run
    from trackplan.planning.plan import plan

    try:
        chromium()
    except CaseError as error:
        pytest.skip(f"BROWSER TEST SKIPPED: {error}")
    case = load_case(CASES / "paper-corner-cell.yaml")
    run = tmp_path / "run"
    write_run(run, plan(case, np.array(CELL_PLACEMENT)), case, report=False)
    written = report_images(run, tmp_path / "images")
    names = [p.name for p in written]
    assert names[:2] == [VIEW_START, VIEW_CLOSEST] and "clearance.png" in names
    start, closest = (image.imread(p) for p in written[:2])
    assert start.shape[:2] == closest.shape[:2] == (VIEW_SIZE[1], VIEW_SIZE[0])
    assert np.mean(np.any(start != closest, axis=2)) > 0.001  # the title at least differs
