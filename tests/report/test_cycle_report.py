"""The report of a case of several seams joined by moves: every section a single seam's
report has (3D view, joint plots, margins, speed, clearance) plus the cycle and the sequence.

The bracket (``cases/bracket-4-fillets.yaml``) is planned once per session (about 10 s
once numba's kernels are cached): the tests are slow.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from trackplan.planning.result import MOVE_KINDS, SEAM
from trackplan.report.cycle import sequence_section
from trackplan.report.cycle_view import cycle_view_spec
from trackplan.report.html_markup import num
from trackplan.report.robot_view import NOMINAL_TRACE, PATH_TRACE, ROBOT_TRACE, robot_view_spec
from trackplan.report.scene import tracking_error
from trackplan.report.speed_plot import speed_figure

pytestmark = pytest.mark.slow


def _gids(figure, gid):
    return [a for ax in figure.axes for a in ax.get_children() if a.get_gid() == gid]


def test_the_report_of_several_seams_has_every_section(bracket, bracket_result, bracket_report):
    plots, report = bracket_report
    names = [path.name for path in plots]
    assert names == ["cycle.png", "joints.png", "speed.png", "clearance.png"]
    html = report.read_text(encoding="utf-8")
    for anchor in (
        'id="view"',
        'id="plot-cycle"',
        'id="plot-joints"',
        'id="plot-speed"',
        'id="plot-clearance"',
        'id="sequence"',
        'href="#sequence"',
        "<h3>Margins</h3>",
    ):
        assert anchor in html, anchor
    assert "Plotly.newPlot" in html
    view = html[html.index('<section id="view">') :]
    assert "The robot runs the whole cycle" in view
    # the joint margins of the whole cycle, one column per joint
    margins = html[html.index("<h3>Margins</h3>") :]
    for j in range(bracket.robot.n_dof):
        assert f"joint {j + 1}" in margins


def test_the_sequence_table_lists_every_seam_in_welding_order(bracket, bracket_result):
    section = sequence_section(bracket_result, bracket)
    rows = re.findall(r"<tr>(.*?)</tr>", section, re.S)
    seam_rows = [r for r in rows if re.search(r"<td[^>]*>\d+</td>", r)][: len(bracket.seams)]
    welded = [seam.name for seam in bracket_result.seams]
    assert len(welded) == len(bracket.seams) == 4
    for order, (row, name) in enumerate(zip(seam_rows, welded, strict=True)):
        assert f">{order + 1}<" in row and f">{name}<" in row
        assert "feasible" in row
        own = bracket_result.seam_checks[order]
        assert f">{num(own.max_tracking_error, scale=1e3, unit='mm')}<" in row
    assert "cycle time" in section and "welding (seam time)" in section
    # the totals add up (to the table's 4 digits)
    assert bracket_result.seam_time + bracket_result.air_time == pytest.approx(
        bracket_result.duration, abs=1e-6
    )
    assert f"{bracket_result.duration:.4g} s" in section


def test_a_single_seam_has_no_sequence_section(corner, corner_result):
    assert sequence_section(corner_result, corner) == ""


def test_the_3d_view_draws_every_seam_and_every_move(bracket, bracket_result):
    spec = cycle_view_spec(robot_view_spec(bracket_result, bracket, 20), bracket_result, bracket)
    names = [trace["name"] for trace in spec["data"]]
    assert PATH_TRACE not in names and NOMINAL_TRACE not in names
    position = bracket_result.trajectory.tool_position
    for span in bracket_result.spans:
        if span.kind != SEAM:
            continue
        label = f"seam {span.label}" + (" (reversed)" if span.reversed else "")
        trace = spec["data"][names.index(label)]
        drawn = np.column_stack([trace["x"], trace["y"], trace["z"]]).astype(float)
        # the seam's trace runs from its first sample to its last (10 µm rounding)
        np.testing.assert_allclose(drawn[0], position[span.first], atol=2e-5)
        np.testing.assert_allclose(drawn[-1], position[span.last], atol=2e-5)
        assert f"{NOMINAL_TRACE}: {span.label}" in names
    for kind in MOVE_KINDS:
        trace = spec["data"][names.index(f"{kind} moves")]
        n_spans = sum(span.kind == kind for span in bracket_result.spans)
        assert sum(x is None for x in trace["x"]) == n_spans - 1  # one gap between spans
        assert trace["line"]["dash"] == "dash"
    # the animation still drives the robot: every frame updates the robot trace
    robot = names.index(ROBOT_TRACE)
    assert all(robot in frame["traces"] for frame in spec["frames"])
    assert all(frame["data"][0]["name"] == ROBOT_TRACE for frame in spec["frames"])


def test_the_report_embeds_the_cycle_view(bracket_report):
    _, report = bracket_report
    html = report.read_text(encoding="utf-8")
    assert '"name":"air moves"' in html.replace(": ", ":")
    assert '"name":"seam boss"' in html.replace(": ", ":")


def test_the_speed_plot_marks_the_seams_and_the_moves(bracket, bracket_result):
    figure = speed_figure(bracket_result, bracket)
    labels = sorted(text.get_text() for text in _gids(figure, "seam-label"))
    assert labels == sorted(bracket.seam_names)
    n_moves = sum(span.kind in MOVE_KINDS for span in bracket_result.spans)
    assert len(_gids(figure, "move")) == 2 * n_moves  # on both axes
    # the axis fits the welding; the moves' peak speed is in the legend
    fastest = 1e3 * float(np.max(bracket_result.trajectory.speed))
    top = figure.axes[0].get_ylim()[1]
    assert top < fastest
    assert top >= 1e3 * max(bracket.task.rated_speed, bracket.task.corner_speed)
    legend = [t.get_text() for t in figure.axes[0].get_legend().get_texts()]
    assert f"moves: up to {fastest:.4g} mm/s, off the axis" in legend
    # each seam's own rated speed over its span: the boss is welded at 15 mm/s
    rated = _gids(figure, "rated-speed")
    levels = sorted({float(s[0][0][1]) for line in rated for s in [line.get_segments()]})
    assert levels == pytest.approx([15.0, 20.0], abs=1e-9)


def test_the_tracking_error_is_each_seams_and_none_on_the_moves(bracket, bracket_result):
    error = tracking_error(bracket_result, bracket)
    for span in bracket_result.spans:
        inner = error[span.first + 1 : span.last]
        if span.kind == SEAM:
            assert np.isfinite(inner).all()
            # within the tolerance, as the checker found (1 µm for the rounding)
            assert np.max(inner) <= bracket.task.tolerance + 1e-6
        else:
            assert np.isnan(inner).all()


def test_the_joint_plot_shades_the_moves_of_a_cycle_only(bracket, bracket_result, corner_result):
    from trackplan.report.joints_plot import joints_figure, move_samples

    figure = joints_figure(bracket_result, bracket, rows=(0,))
    bands = _gids(figure, "move")
    assert len(bands) == bracket.robot.n_dof  # one polygon per panel
    moving = move_samples(bracket_result)
    air = next(span for span in bracket_result.spans if span.kind == "air")
    assert moving[air.first : air.last + 1].all()
    assert not moving[bracket_result.spans[1].first + 1 : bracket_result.spans[1].last].any()
    assert not move_samples(corner_result).any()


def test_the_key_figures_of_a_cycle_compare_welding_with_each_seams_rated_speed(
    bracket, bracket_result
):
    from trackplan.report.html_result import figures_table

    html = figures_table(bracket_result, bracket)
    ideal = sum(
        seam.plan.path_length / bracket.seams[seam.index].task.rated_speed
        for seam in bracket_result.seams
    )
    # boss 188.5 mm at 15 mm/s, the rest 400 mm at 20 mm/s
    assert ideal == pytest.approx(0.06 * np.pi / 0.015 + 0.4 / 0.02, rel=1e-3)
    assert "Σ L / v_r over the seams" in html and f"{ideal:.4g} s" in html


def test_slow_downs_of_a_cycle_name_their_seam_and_sit_in_its_span(bracket, bracket_result):
    import dataclasses

    from trackplan.report.html_result import slowdowns_table
    from trackplan.report.speed_plot import slowdown_times
    from trackplan.timing import SlowDown

    # a made-up slow-down 2 cm into the second seam welded
    slow = SlowDown(0.02, 0.04, 0.01, 0.02, "joint 4 velocity")
    second = bracket_result.seams[1]
    seams = list(bracket_result.seams)
    seams[1] = dataclasses.replace(second, plan=dataclasses.replace(second.plan, slowdowns=(slow,)))
    result = dataclasses.replace(bracket_result, seams=tuple(seams), slowdowns=(slow,))
    html = slowdowns_table(result)
    assert ">seam</th>" in html and f">{second.name}</td>" in html
    ((t0, t1),) = slowdown_times(result)
    span = next(p for p in result.spans if p.kind == SEAM and p.seam == second.index)
    trajectory = result.trajectory
    assert span.first * trajectory.sample_time < t0 < t1 < span.last * trajectory.sample_time
    # where the seam's own arc length reaches 2 cm and 4 cm (one sample)
    rows = slice(span.first, span.last + 1)
    for t, s in ((t0, 0.02), (t1, 0.04)):
        k = np.searchsorted(trajectory.s[rows], s)
        assert t == pytest.approx(trajectory.t[rows][k], abs=trajectory.sample_time)


def test_the_case_section_lists_every_seam_as_written(bracket, bracket_result):
    from trackplan.report.html_case import case_section

    html = case_section(bracket_result, bracket)
    for seam in bracket.seams:
        assert f">{seam.name}</th>" in html  # the first column of a row
    assert "15 mm/s" in html and "20 mm/s" in html  # the boss's own rated speed, the rest's
    # every segment as written: 1 + 1 + 1 (the boss's arc) + 2 (the gusset's lines)
    assert html.count(">line<") + html.count(">arc<") == 5
