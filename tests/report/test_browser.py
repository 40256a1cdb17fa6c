"""report.html in headless Chromium: it loads offline, without errors, and the 3D view animates.

Needs Debian's Chromium (``make browser`` installs it) and the ``playwright`` package, used
only to drive that browser (``playwright install`` is never run: it would download one).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tests.docs.screenshots import CHROMIUM, CHROMIUM_ARGS
from tests.report.conftest import REPORT_FRAMES
from trackplan.report import VIEW_ID
from trackplan.report.robot_view import ROBOT_TRACE, frame_name
from trackplan.report.scene import chain_points, frame_indices

pytestmark = pytest.mark.browser


ROBOT_XYZ = (
    "(name) => { const trace = document.getElementById('"
    + VIEW_ID
    + "').data.find((t) => t.name === name);"
    " return [Array.from(trace.x), Array.from(trace.y), Array.from(trace.z)]; }"
)


ACTIVE_STEP = f"() => document.getElementById('{VIEW_ID}').layout.sliders[0].active"


# true once the slider left step `later` and the robot drawn is the active step's frame
SHOWS_ACTIVE_STEP = """([id, name, later]) => {
    const gd = document.getElementById(id);
    const step = gd.layout.sliders[0].active;
    if (step >= later) return false;
    const frame = gd._transitionData._frames[step];
    const drawn = gd.data.find((t) => t.name === name);
    const wanted = frame.data[0];
    return drawn.x.every((x, i) => x === wanted.x[i]) && drawn.z.every((z, i) => z === wanted.z[i]);
}"""

# true once the robot drawn is the pose of a frame after `step`
SHOWS_A_LATER_FRAME = """([id, name, step]) => {
    const gd = document.getElementById(id);
    const drawn = gd.data.find((t) => t.name === name);
    return gd._transitionData._frames.slice(step + 1).some((frame) =>
        drawn.x.every((x, i) => x === frame.data[0].x[i]));
}"""


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="BROWSER TEST SKIPPED: the playwright package is missing"
    )
    if not CHROMIUM.exists():
        pytest.skip(f"BROWSER TEST SKIPPED: no Chromium at {CHROMIUM}; run `make browser`")
    with sync_api.sync_playwright() as playwright:
        try:
            chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        except sync_api.Error as error:
            pytest.skip(f"BROWSER TEST SKIPPED: Chromium at {CHROMIUM} did not start: {error}")
        yield chromium
        chromium.close()


@pytest.mark.slow  # about 9 s: Chromium started, a report opened and animated
def test_report_view_animates_without_errors(browser, report_file, tmp_path, corner, corner_result):
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.set_default_timeout(120_000)  # a loaded CI machine parses 5 MB of plotly.js slowly
    problems: list[str] = []
    page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda error: problems.append(str(error)))
    page.on(
        "request",
        lambda r: problems.append(f"network request {r.url}") if r.url.startswith("http") else None,
    )
    page.goto(report_file.as_uri())
    page.wait_for_function(
        f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
        " return gd && gd.data && gd._transitionData && gd._transitionData._frames.length > 0; }"
    )
    names = page.evaluate(f"() => document.getElementById('{VIEW_ID}').data.map((t) => t.name)")
    assert ROBOT_TRACE in names and "planned path" in names
    n_frames = page.evaluate(
        f"() => document.getElementById('{VIEW_ID}')._transitionData._frames.length"
    )
    assert n_frames == REPORT_FRAMES

    idx = frame_indices(corner_result.trajectory.n_samples, REPORT_FRAMES)
    start = np.array(page.evaluate(ROBOT_XYZ, ROBOT_TRACE)).T
    expected = chain_points(corner.robot, corner_result.trajectory.q[idx])
    np.testing.assert_allclose(start, expected[0], atol=1e-5)

    # what a slider step does: animate to a later frame
    later = REPORT_FRAMES * 3 // 4
    page.evaluate(
        "async ([id, name]) => { await Plotly.animate(document.getElementById(id), [name],"
        " {mode: 'immediate', frame: {duration: 0, redraw: true}, transition: {duration: 0}}); }",
        [VIEW_ID, frame_name(later)],
    )
    moved = np.array(page.evaluate(ROBOT_XYZ, ROBOT_TRACE)).T
    assert np.max(np.abs(moved - start)) > 0.01
    np.testing.assert_allclose(moved, expected[later], atol=1e-5)

    # a click on the slider rail a quarter of the way along jumps to that frame
    rail = page.locator(f"#{VIEW_ID} .slider-rail-touch-rect")
    box = rail.bounding_box()
    # let the animation the click starts finish before play interrupts anything
    page.evaluate(
        "(id) => { window.sliderDone = false; document.getElementById(id)"
        ".on('plotly_animated', () => { window.sliderDone = true; }); }",
        VIEW_ID,
    )
    rail.click(position={"x": 0.25 * box["width"], "y": 0.5 * box["height"]})
    page.wait_for_function(SHOWS_ACTIVE_STEP, arg=[VIEW_ID, ROBOT_TRACE, later])
    page.wait_for_function("() => window.sliderDone")
    clicked = page.evaluate(ACTIVE_STEP)
    assert 0 < clicked < later
    np.testing.assert_allclose(
        np.array(page.evaluate(ROBOT_XYZ, ROBOT_TRACE)).T, expected[clicked], atol=1e-5
    )

    # play runs the animation on from there (the robot leaves the clicked frame's pose
    # for a later frame's); pause stops it
    page.locator(f"#{VIEW_ID} .updatemenu-button").filter(has_text="play").click()
    page.wait_for_function(SHOWS_A_LATER_FRAME, arg=[VIEW_ID, ROBOT_TRACE, clicked])
    page.locator(f"#{VIEW_ID} .updatemenu-button").filter(has_text="pause").click()

    screenshot = tmp_path / "report-view.png"
    page.locator("#view").screenshot(path=str(screenshot))
    assert screenshot.stat().st_size > 10_000
    page.close()
    assert not problems, problems


@pytest.mark.slow
def test_the_report_of_several_seams_loads_without_errors(browser, bracket, bracket_report):
    _, report = bracket_report
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.set_default_timeout(120_000)
    problems: list[str] = []
    page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda error: problems.append(str(error)))
    page.on(
        "request",
        lambda r: problems.append(f"network request {r.url}") if r.url.startswith("http") else None,
    )
    page.goto(report.as_uri())
    page.wait_for_function(
        f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
        " return gd && gd.data && gd._transitionData && gd._transitionData._frames.length > 0; }"
    )
    names = page.evaluate(f"() => document.getElementById('{VIEW_ID}').data.map((t) => t.name)")
    assert ROBOT_TRACE in names
    assert {"approach moves", "retract moves", "air moves"} <= set(names)
    assert sum(name.startswith("seam ") for name in names) == len(bracket.seams)
    # the sections a single seam's report has, and the sequence, are on the page
    for anchor in ("view", "sequence", "plot-joints", "plot-speed", "plot-clearance"):
        assert page.locator(f"#{anchor}").count() == 1, anchor
    start = np.array(page.evaluate(ROBOT_XYZ, ROBOT_TRACE)).T
    page.evaluate(
        "async ([id, name]) => { await Plotly.animate(document.getElementById(id), [name],"
        " {mode: 'immediate', frame: {duration: 0, redraw: true}, transition: {duration: 0}}); }",
        [VIEW_ID, frame_name(REPORT_FRAMES // 2)],
    )
    moved = np.array(page.evaluate(ROBOT_XYZ, ROBOT_TRACE)).T
    assert np.max(np.abs(moved - start)) > 0.01  # the robot follows the cycle
    page.close()
    assert not problems, problems


FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
MESHED_URDF = FIXTURES / "meshed_robot" / "meshed_robot.urdf"
OPEN_BUDGET = 2.0  # s: the 3D view's first drawing, from the start of the navigation
OPEN_CEILING = 8.0  # s of wall time: far above what a loaded 2-core machine measures
DRAWN = f"() => performance.getEntriesByName('{VIEW_ID} drawn').length > 0"


def open_times(browser, report: Path, repeats: int = 3) -> list[tuple[float, float]]:
    """Open ``report`` ``repeats`` times: per opening (wall time, main-thread CPU time), s,
    from the start of the navigation to the 3D view's first drawing, with no console error.

    The wall time is the page's own mark (``performance.mark('robot-view drawn')``, whose
    time counts from the navigation's start); the CPU time is Chromium's TaskDuration of the
    page's main thread in thread ticks, which the other processes of a loaded machine do
    not inflate.
    """
    times = []
    problems: list[str] = []
    for _ in range(repeats):
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda error: problems.append(str(error)))
        cdp = page.context.new_cdp_session(page)
        cdp.send("Performance.enable", {"timeDomain": "threadTicks"})
        page.goto(report.as_uri(), wait_until="commit")
        page.wait_for_function(DRAWN, timeout=120_000, polling=10)
        metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
        wall = page.evaluate(f"() => performance.getEntriesByName('{VIEW_ID} drawn')[0].startTime")
        page.wait_for_function(
            f"() => document.getElementById('{VIEW_ID}')._transitionData._frames.length > 0"
        )
        page.close()
        assert not problems, problems
        times.append((wall / 1e3, metrics["TaskDuration"]))
    return times


@pytest.mark.slow  # about 15 s: a report written and opened three times
def test_a_meshed_robot_report_opens_in_two_seconds(browser, tmp_path, corner, corner_result):
    from trackplan.io.urdf_robot import robot_from_urdf_file
    from trackplan.report.run_report import write_run_report

    robot = robot_from_urdf_file(MESHED_URDF, assume_limits=True)
    case = dataclasses.replace(corner, robot=robot)
    _, report = write_run_report(corner_result, case, tmp_path, None, None, parallel=False)
    times = open_times(browser, report)
    walls, cpus = zip(*times, strict=True)
    note = ", ".join(f"{wall:.2f} s ({cpu:.2f} s CPU)" for wall, cpu in times)
    assert min(cpus) <= OPEN_BUDGET, f"the 3D view's first drawing took {note}"
    assert min(walls) <= OPEN_CEILING, f"the 3D view's first drawing took {note}"
