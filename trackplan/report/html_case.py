"""The report's Case section: the robot, the path, the task and the placement search set-up."""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.frames import rpy_from_matrix
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.planning.result import PlanResult
from trackplan.report.html_markup import Cell, esc, grid, key_values, num, vector
from trackplan.robots.families import ik_family
from trackplan.tool import ToolFrame


def _describe_segment(segment: SegmentSpec) -> tuple[str, str]:
    if isinstance(segment, LineSpec):
        return "line", f"to {vector(segment.to)} m"
    if isinstance(segment, ArcSpec):
        weld = segment.weld_normal
        return "arc", (
            f"centre {vector(segment.center)} m, normal {vector(segment.normal)}, "
            f"angle {num(segment.angle)} rad ({num(np.degrees(segment.angle))}°)"
            + ("" if weld is None else f", weld normal {vector(weld)} at its start, turning")
        )
    if isinstance(segment, PointsSpec):
        normals = "" if segment.normals is None else " with weld normals"
        return "points", f"{len(segment.points)} sampled points{normals}"
    return type(segment).__name__, ""


_TCP_SOURCES = {"case": "the case's tcp", "robot": "the robot's tool"}


def _tcp_text(case: Case) -> str:
    """The TCP used, ``Trans(xyz) · RPY(rpy)`` in the flange, and where it comes from
    (escaped HTML)."""
    if case.tcp_source == "none":
        return "none (tool = flange)"
    T = case.robot.T_flange_tool
    text = (
        f"xyz {vector(T[:3, 3])} m, rpy {vector(rpy_from_matrix(T[:3, :3]))} rad "
        f"({_TCP_SOURCES[case.tcp_source]}"
    )
    replaced = case.robot_tool is not None and not np.allclose(case.robot_tool, np.eye(4))
    return esc(text + (", in place of the robot's own tool)" if replaced else ")"))


def case_section(result: PlanResult, case: Case) -> str:
    """The Case section of ``report.html`` (``id="case"``)."""
    robot, task, bounds = case.robot, case.task, case.bounds
    joint_rows = [
        [
            f"{j + 1} ({robot.joint_names[j]})",
            vector(robot.origins[j][:3, 3]),
            vector(robot.axes[j]),
            f"[{num(robot.q_min[j])}, {num(robot.q_max[j])}]",
            num(robot.v_max[j]),
            num(robot.a_max[j]),
            num(robot.j_max[j]),
            num(case.objective.weights[j]) if j < len(case.objective.weights) else "–",
        ]
        for j in range(robot.n_dof)
    ]
    robot_html = key_values(
        [
            ("name", esc(robot.name)),
            ("joints", str(robot.n_dof)),
            ("IK family", esc(ik_family(robot).name)),
            ("tool offset", _tcp_text(case)),
            *(("assumption", esc(note)) for note in robot.assumptions),
            ("source", esc(robot.source or "–")),
        ]
    ) + grid(
        [
            "joint",
            "origin xyz [m]",
            "axis",
            "q range [rad]",
            "q̇ max [rad/s]",
            "q̈ max [rad/s²]",
            "q⃛ max [rad/s³]",
            "weight C_i",
        ],
        joint_rows,
    )
    if case.paths:
        path_html = _seams_html(result, case)
    else:
        segments: list[list[Cell]] = [
            [str(i + 1), *((esc(text), "text") for text in _describe_segment(s))]
            for i, s in enumerate(case.segments)
        ]
        path_html = key_values(
            [
                ("start", f"{vector(case.start)} m"),
                ("segments", str(len(case.segments))),
                ("nominal length", num(result.path_length, unit="m")),
            ]
        ) + grid(["#", "kind", "geometry (definition frame)"], segments)
    task_html = key_values(
        [
            ("rated speed v_r", num(task.rated_speed, scale=1e3, unit="mm/s")),
            ("corner speed cap v_t^max", num(task.corner_speed, scale=1e3, unit="mm/s")),
            ("tolerance ρ", num(task.tolerance, scale=1e3, unit="mm")),
            ("sample time Ts", num(task.sample_time, scale=1e3, unit="ms")),
            ("tool orientation", _tool_text(task.tool)),
            ("time law", esc(task.timing)),
        ]
    )
    search_html = key_values(
        [
            ("lower bound X", vector(bounds.lower)),
            ("upper bound X", vector(bounds.upper)),
            ("reach of (x, y, z)", f"{num(bounds.reach[0])} – {num(bounds.reach[1])} m"),
            (
                "objective",
                f"Eq. 8, time weight {num(case.objective.time_weight)} per s, "
                f"{esc(case.objective.penalty)} penalty",
            ),
            (
                "optimizer",
                f"{esc(case.optimizer.method)}, population {case.optimizer.population}, "
                f"seed {case.optimizer.seed}, "
                f"budget {esc(case.optimizer.budget or 'method default')}",
            ),
            ("case file", esc(case.source or "–")),
        ]
    )
    external = _external_html(case)
    return (
        '<section id="case"><h2>Case</h2>'
        f'<div class="cols"><div><h3>Robot</h3>{robot_html}</div>{external}</div>'
        f'<div class="cols"><div><h3>Path</h3>{path_html}</div><div><h3>Task</h3>{task_html}</div>'
        f"<div><h3>Placement search</h3>{search_html}</div></div></section>"
    )


def _seams_html(result: PlanResult, case: Case) -> str:
    """The seams of a case file's ``paths:`` as written: per segment its seam, the seam's
    start and rated speed, and the segment; with the sequence mode and approach distance."""
    rows: list[list[Cell]] = []
    for seam in case.seams:
        for i, segment in enumerate(seam.segments):
            first = i == 0
            rows.append(
                [
                    (esc(seam.name), "text") if first else "",
                    f"{vector(seam.start)} m" if first else "",
                    num(seam.task.rated_speed, scale=1e3, unit="mm/s") if first else "",
                    *((esc(text), "text") for text in _describe_segment(segment)),
                ]
            )
    sequencing = case.sequencing
    return key_values(
        [
            ("seams", str(len(case.seams))),
            ("nominal length", f"{num(result.path_length, unit='m')} (all seams)"),
            ("sequence", esc(sequencing.sequence)),
            ("approach", num(sequencing.approach, scale=1e3, unit="mm")),
        ]
    ) + grid(["seam", "start", "rated speed", "kind", "geometry (definition frame)"], rows)


def _external_html(case: Case) -> str:
    """The track and the positioner of the case (``docs/positioner.md``), or nothing."""
    parts = []
    track = case.track
    if track is not None:
        parts.append(
            key_values(
                [
                    ("track axis", vector(track.axis)),
                    ("track range", f"[{num(track.lower)}, {num(track.upper)}] m"),
                    (
                        "track limits",
                        f"{num(track.velocity)} m/s, {num(track.acceleration)} m/s², "
                        f"{num(track.jerk)} m/s³",
                    ),
                ]
            )
        )
    positioner = case.positioner
    if positioner is not None:
        chain = positioner.chain
        rows = [
            [
                esc(chain.joint_names[j]),
                vector(chain.origins[j][:3, 3]),
                vector(chain.axes[j]),
                f"[{num(chain.q_min[j])}, {num(chain.q_max[j])}]",
                num(chain.v_max[j]),
                num(chain.a_max[j]),
                num(chain.j_max[j]),
            ]
            for j in range(chain.n_dof)
        ]
        searched = "" if not len(positioner.searched) else " (searched)"
        parts.append(
            key_values(
                [
                    ("positioner", esc(positioner.model or chain.name)),
                    (
                        "positioner pose",
                        f"{vector(positioner.pose)} (m, rad in the cell){searched}",
                    ),
                    *(("assumption", esc(note)) for note in chain.assumptions),
                    ("source", esc(chain.source or "–")),
                ]
            )
            + grid(
                [
                    "axis",
                    "origin xyz [m]",
                    "axis",
                    "q range [rad]",
                    "q̇ max [rad/s]",
                    "q̈ max [rad/s²]",
                    "q⃛ max [rad/s³]",
                ],
                rows,
            )
        )
    if not parts:
        return ""
    return f'<div id="external-axes-case"><h3>Track and positioner</h3>{"".join(parts)}</div>'


def _tool_text(tool) -> str:  # type: ignore[no-untyped-def]
    """The tool spec in one line (docs/tool.md)."""
    if tool.frame == ToolFrame.PART:
        where = f"part frame, roll/pitch/yaw {vector(tool.rpy)} rad"
    else:
        normal = (
            "the path segments' own weld normals"
            if tool.normal is None and tool.normals is None
            else f"normal {vector(tool.normal)}"
            if tool.normals is None
            else "normals " + " ".join(vector(n) for n in tool.normals)
        )
        where = (
            f"seam frame, {normal}, work {tool.work_angle:.4g} rad, "
            f"travel {tool.travel_angle:.4g} rad"
        )
    return f"{where}; spin {tool.spin}"
