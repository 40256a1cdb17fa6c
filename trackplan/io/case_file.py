"""Case files (YAML): the robot, the path, the task and the search settings of one job.

The format, every key with its unit and default, and the validation rules are in
``docs/files.md``. :func:`load_case` reads a file into the pure dataclasses of
:mod:`trackplan.case`; every problem becomes one :class:`~trackplan.errors.CaseError`
naming the file, the key path (``path.segments[2].arc.normal``) and what is expected.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.case import (
    PLACEMENT_KEYS,
    Case,
    Objective,
    OptimizerSettings,
    PlacementBounds,
    Seam,
    Sequencing,
    Task,
)
from trackplan.choices import OBJECTIVE_KINDS, Method, Penalty, Timing
from trackplan.io.case_axes import axes_problems, load_positioner_chain, with_axes
from trackplan.io.case_cad import expand_cad, with_part_body
from trackplan.io.case_redundancy import as_redundancy
from trackplan.io.case_schema import (
    CaseModel,
    ObjectiveModel,
    PathModel,
    PlacementModel,
    PointsFileModel,
    SeamModel,
    SeamTaskModel,
    SegmentModel,
    SinglePathCaseModel,
)
from trackplan.io.case_tcp import misplaced_tool, tcp_problems, with_tcp
from trackplan.io.cell_file import build_cell, cell_problems
from trackplan.io.points_file import load_points_csv
from trackplan.io.robot_file import PayloadModel, as_payload, load_robot_spec, payload_problems
from trackplan.io.sizes import size_problems
from trackplan.io.tool_file import as_spec, path_tool_problems
from trackplan.io.yaml_input import (
    Loc,
    Problem,
    key_path,
    parse_key_path,
    parse_yaml,
    raise_first,
    read_text,
    show,
    validate_model,
)
from trackplan.paths import NominalPath, check_segments
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.robots.model import Robot

PAPER_WEIGHTS = (0.3, 0.2, 0.2, 0.1, 0.1, 0.1)
"""C_i of the paper's Eq. 8 for a 6-joint arm (the paper prints five; the sixth is 0.1)."""


def load_case(file: str | Path, *, assume_limits: bool = False) -> Case:
    """Read a case file.

    Parameters
    ----------
    file
        Path of the YAML case file. Robot files and points files it names are read
        relative to its folder.
    assume_limits
        Fill a URDF robot's missing acceleration and jerk limits by the documented rule
        (``docs/robots.md``) instead of refusing it; the robot records the assumption.

    Returns
    -------
    Case

    Raises
    ------
    CaseError
        The first problem found: an unreadable file, a YAML syntax error, a schema
        problem (in file order), an unknown robot or a bad robot file, an unreadable
        points file, then bad values (in file order).
    """
    text = read_text(file, what="case file", hint=" (put long sampled curves in a points file)")
    return load_case_text(
        text, file=str(file), base_dir=Path(file).parent, assume_limits=assume_limits
    )


def load_case_text(
    text: str,
    file: str | None = None,
    base_dir: str | Path | None = None,
    *,
    assume_limits: bool = False,
) -> Case:
    """Build a case from the text of a case file.

    Parameters
    ----------
    text
        YAML text in the case file format.
    file
        The file the text came from, for messages and :attr:`Case.source`.
    base_dir
        Folder that relative robot and points file names start from; by default the
        folder of ``file``, else the working directory.
    assume_limits
        As for :func:`load_case`.

    Returns
    -------
    Case

    Raises
    ------
    CaseError
        See :func:`load_case`.
    """
    base = Path(base_dir) if base_dir is not None else Path(file).parent if file else Path()
    return load_case_data(parse_yaml(text, file), file, base, assume_limits=assume_limits)


def load_case_data(
    data: Any, file: str | None, base_dir: str | Path, *, assume_limits: bool = False
) -> Case:
    """Build a case from the parsed data of a case file (a study's overrides applied to it).

    Parameters
    ----------
    data
        The YAML document as loaded: a mapping in the case file format (``cad:`` seams are
        derived from the part first, :func:`trackplan.io.case_cad.expand_cad`).
    file, base_dir
        The file the data came from (messages, :attr:`Case.source`) and the folder that
        relative robot, points and part file names start from.
    assume_limits
        As for :func:`load_case`.

    Returns
    -------
    Case

    Raises
    ------
    CaseError
        See :func:`load_case`.
    """
    base = Path(base_dir)
    data, cad = expand_cad(data, file, base)  # cad: seams as plain start and segments
    several = isinstance(data, dict) and "paths" in data
    raise_first(misplaced_tool(data), data, file)
    model = validate_model(CaseModel if several else SinglePathCaseModel, data, file)
    raise_first(_seam_key_problems(model), data, file)
    robot = load_robot_spec(model.robot, base, case_file=file, assume_limits=assume_limits)
    robot, robot_tool = with_tcp(robot, model.tcp)
    seams = _seam_models(model)
    paths = [
        (
            _array(seam.start),
            tuple(
                _segment(segment, base, file, (*loc, "segments", k))
                for k, segment in enumerate(seam.segments)
            ),
        )
        for loc, seam in seams
    ]
    start, segments = paths[0]
    problems = [
        *(
            problem
            for (loc, _), (seam_start, seam_segments) in zip(seams, paths, strict=True)
            for problem in _path_problems(seam_start, seam_segments, model, base, loc)
        ),
        *_home_problems(model.home, robot),
        *_placement_problems(
            model.placement, _ranges(model.placement, robot), _reach(model.placement, robot)
        ),
        *_objective_problems(model.objective, robot),
        *(cell_problems(model.cell, robot.n_dof) if model.cell is not None else []),
        *_objective_kind_problems(model.objective, robot),
        *_payload_problems(model.payload, robot),
        *tcp_problems(model.tcp),
        *axes_problems(model, seams, paths),
    ]
    # sizes before any costly path work: a path too long for memory is refused unbuilt
    sizes = [] if problems else _size_problems(seams, paths, model, robot.n_dof)
    for (loc, seam), (seam_start, seam_segments) in zip(seams, paths, strict=True):
        built = not problems and not sizes
        nominal = NominalPath.from_specs(seam_start, seam_segments) if built else None
        own = seam.task if isinstance(seam, SeamModel) else None
        task = own if own is not None and (own.tool, own.tool_rpy) != (None, None) else model.task
        at = loc if task is own else ()
        problems += path_tool_problems(task.tool, task.tool_rpy, nominal, seam_segments, loc, at)
    raise_first(problems, data, file)
    raise_first(sizes, data, file)
    if model.payload is not None and robot.dynamics is not None:
        dynamics = dataclasses.replace(robot.dynamics, payload=as_payload(model.payload))
        robot = dataclasses.replace(robot, dynamics=dynamics)
    case = dataclasses.replace(_case(model, robot, start, segments, file), robot_tool=robot_tool)
    if model.paths is not None:
        case = _with_seams(case, model, paths)
    case = with_axes(case, model, load_positioner_chain(model, base, file, assume_limits))
    if model.cell is not None:
        case = dataclasses.replace(case, cell=build_cell(model.cell, base, file, robot))
    return with_part_body(case, cad)


def _size_problems(
    seams: list[tuple[Loc, PathModel]],
    paths: list[tuple[np.ndarray, tuple[SegmentSpec, ...]]],
    model: CaseModel,
    n_dof: int,
) -> list[Problem]:
    """The size problems (:func:`~trackplan.io.sizes.size_problems`) of the first seam that
    has any, located in the file."""
    for (loc, seam), (seam_start, seam_segments) in zip(seams, paths, strict=True):
        own = seam.task if isinstance(seam, SeamModel) else None
        sizes = size_problems(
            seam_start,
            seam_segments,
            n_dof=n_dof,
            rated_speed=(
                own.rated_speed
                if own is not None and own.rated_speed is not None
                else model.task.rated_speed
            ),
            sample_time=model.task.sample_time,
            population=model.optimizer.population,
        )
        if sizes:
            return [(loc + where[1:] if where[:1] == ("path",) else where, m) for where, m in sizes]
    return []


def _case(
    model: CaseModel,
    robot: Robot,
    start: np.ndarray,
    segments: tuple[SegmentSpec, ...],
    file: str | None,
) -> Case:
    task, placement = model.task, model.placement
    objective, optimizer = model.objective, model.optimizer
    weights = objective.weights
    if weights is None:
        weights = list(PAPER_WEIGHTS) if robot.n_dof == len(PAPER_WEIGHTS) else [1.0] * robot.n_dof
    ranges = np.array(list(_ranges(placement, robot).values()), dtype=float)
    return Case(
        name=model.name,
        robot=robot,
        start=start,
        segments=segments,
        task=Task(
            rated_speed=task.rated_speed,
            corner_speed=task.rated_speed if task.corner_speed is None else task.corner_speed,
            tolerance=task.tolerance,
            sample_time=task.sample_time,
            tool=as_spec(task.tool, task.tool_rpy),
            timing=Timing(task.timing),
            redundancy=as_redundancy(task.redundancy),
        ),
        bounds=PlacementBounds(
            lower=_array(ranges[:, 0]),
            upper=_array(ranges[:, 1]),
            reach=_reach(placement, robot),
            example=None if placement.example is None else _array(placement.example),
        ),
        objective=Objective(
            weights=_array(weights),
            time_weight=objective.time_weight,
            penalty=Penalty(objective.penalty),
            flat_penalty=objective.flat_penalty,
            kind=objective.kind,
            mix=dict(objective.mix or {}),
        ),
        optimizer=OptimizerSettings(
            method=Method(optimizer.method),
            population=optimizer.population,
            seed=optimizer.seed,
            budget=optimizer.budget,
            restarts=optimizer.restarts,
        ),
        source=file,
    )


def _seam_models(model: CaseModel) -> list[tuple[Loc, PathModel]]:
    """Every path of the case with its location: ``path``, or each entry of ``paths``."""
    if model.paths is not None:
        return [(("paths", k), seam) for k, seam in enumerate(model.paths)]
    assert model.path is not None  # _seam_key_problems requires one of them
    return [(("path",), model.path)]


def _seam_key_problems(model: CaseModel) -> list[Problem]:
    """``path`` or ``paths`` (not both, not neither); unique seam names; the cycle keys
    only with ``paths``."""
    if model.path is not None and model.paths is not None:
        return [
            (
                ("paths",),
                "give path (one seam) or paths (several named seams), not both; "
                "move path into paths as one named entry",
            )
        ]
    if model.path is None and model.paths is None:
        return [(("path",), "required key is missing")]
    if model.paths is None:
        return [
            ((key,), f"{key} is only used with paths (several seams)")
            for key in ("sequence", "approach", "home")
            if getattr(model, key) is not None
        ]
    problems: list[Problem] = []
    if model.objective.kind != "travel":
        problems.append(
            (
                ("objective", "kind"),
                f"kind {model.objective.kind} is not supported with several seams (paths): "
                "they minimise travel (Eq. 8) with objective.time_weight on the cycle time",
            )
        )
    first: dict[str, int] = {}
    for k, seam in enumerate(model.paths):
        if seam.name in first:
            problems.append(
                (
                    ("paths", k, "name"),
                    f"seam name {seam.name!r} is used twice (also paths[{first[seam.name]}]"
                    ".name); give each seam its own name",
                )
            )
        first.setdefault(seam.name, k)
    return problems


def _home_problems(home: list[float] | None, robot: Robot) -> list[Problem]:
    """``home``: one value per joint, inside the joint limits."""
    if home is None:
        return []
    if len(home) != robot.n_dof:
        return [
            (
                ("home",),
                f"expected {robot.n_dof} joint values (one per joint of {robot.name}), rad, "
                f"got {len(home)}: {show(home)}",
            )
        ]
    return [
        (
            ("home", i),
            f"joint {i + 1} at {value:.6g} rad is outside its limits "
            f"[{robot.q_min[i]:.6g}, {robot.q_max[i]:.6g}] rad",
        )
        for i, value in enumerate(home)
        if not robot.q_min[i] <= value <= robot.q_max[i]
    ]


def _with_seams(
    case: Case, model: CaseModel, paths: list[tuple[np.ndarray, tuple[SegmentSpec, ...]]]
) -> Case:
    """The case with its seams (``paths``), their tasks and the sequencing settings."""
    assert model.paths is not None
    seams = []
    for seam, (start, segments) in zip(model.paths, paths, strict=True):
        own = seam.task or SeamTaskModel()
        task = case.task
        rated = task.rated_speed if own.rated_speed is None else own.rated_speed
        if own.corner_speed is not None:
            corner = own.corner_speed
        elif model.task.corner_speed is not None:
            corner = model.task.corner_speed
        else:
            corner = rated
        tool = task.tool
        if own.tool is not None or own.tool_rpy is not None:
            tool = as_spec(own.tool, own.tool_rpy)
        seams.append(
            Seam(
                name=seam.name,
                start=start,
                segments=segments,
                task=dataclasses.replace(
                    task,
                    rated_speed=rated,
                    corner_speed=corner,
                    tolerance=task.tolerance if own.tolerance is None else own.tolerance,
                    tool=tool,
                    redundancy=(
                        task.redundancy if own.redundancy is None else as_redundancy(own.redundancy)
                    ),
                ),
                reversible=seam.reversible,
            )
        )
    sequencing = Sequencing(
        sequence=model.sequence or "optimize",
        approach=0.0 if model.approach is None else model.approach,
        home=None if model.home is None else _array(model.home),
    )
    first = seams[0]
    return dataclasses.replace(
        case,
        start=first.start,
        segments=first.segments,
        task=first.task,
        paths=tuple(seams),
        sequencing=sequencing,
    )


def _array(values: Any) -> np.ndarray:
    """A read-only float64 copy."""
    array = np.array(values, dtype=float)
    array.flags.writeable = False
    return array


def _segment(
    segment: SegmentModel, base: Path, file: str | None, loc: tuple[str | int, ...]
) -> SegmentSpec:
    if segment.line is not None:
        return LineSpec(to=_array(segment.line.to))
    if segment.arc is not None:
        arc = segment.arc
        weld = None if arc.weld_normal is None else _array(arc.weld_normal)
        return ArcSpec(_array(arc.center), _array(arc.normal), arc.angle, weld)
    if isinstance(segment.points, PointsFileModel):
        key = key_path((*loc, "points", "file"))
        rows = load_points_csv(base / segment.points.file, file, key)
    else:  # one width, checked by the schema
        rows = np.array(segment.points, dtype=float)
    if rows.shape[1] == 6:
        return PointsSpec(points=_array(rows[:, :3]), normals=_array(rows[:, 3:]))
    return PointsSpec(points=_array(rows))


# --------------------------------------------------------------------------- value checks


def _path_problems(
    start: np.ndarray,
    segments: tuple[SegmentSpec, ...],
    model: CaseModel,
    base: Path,
    at: Loc = ("path",),
) -> list[Problem]:
    """Degenerate geometry (:func:`trackplan.paths.check_segments`), located in the file
    (``at``: the path's location, ``path`` or ``paths[k]``)."""
    problems: list[Problem] = []
    for key, message in check_segments(start, segments):
        loc = (*at, *parse_key_path(key)[1:])
        csv = _points_file(model, loc, len(at))
        problems.append((loc, f"{message} (in {base / csv})" if csv else message))
    return problems


def _points_file(model: CaseModel, loc: Loc, depth: int = 1) -> str | None:
    """The CSV file a problem location points into, if any (``loc[:depth]`` locates the
    path)."""
    rest = loc[depth:]
    if len(rest) > 1 and rest[0] == "segments" and isinstance(rest[1], int):
        path = model.path if depth == 1 else model.paths[int(loc[1])] if model.paths else None
        if path is None:
            return None
        points = path.segments[rest[1]].points
        if isinstance(points, PointsFileModel):
            return points.file
    return None


def position_range(robot: Robot) -> tuple[float, float]:
    """Default search range of x, y and z: ± the robot's reach, rounded down to the cm, m.

    For the PUMA560 (reach 0.877 m) this is the paper's ±0.87 m (Eq. 31).
    """
    reach = math.floor(robot.reach * 100.0) / 100.0
    return (-reach, reach)


def _ranges(placement: PlacementModel, robot: Robot) -> dict[str, tuple[float, float]]:
    """Search range [min, max] of each placement key: the case's, else the default."""
    ranges = {}
    for key in PLACEMENT_KEYS:
        value = getattr(placement, key)
        if value is None:
            ranges[key] = position_range(robot)
        else:
            ranges[key] = (float(value[0]), float(value[1]))
    return ranges


def _reach(placement: PlacementModel, robot: Robot) -> tuple[float, float]:
    """The placement reach range: the case's, else the robot's default, m."""
    if placement.reach is None:
        return robot.default_placement_reach
    return (placement.reach[0], placement.reach[1])


def _placement_problems(
    placement: PlacementModel, ranges: dict[str, tuple[float, float]], reach: tuple[float, float]
) -> list[Problem]:
    problems: list[Problem] = []
    for key in PLACEMENT_KEYS:
        low, high = ranges[key]
        if low > high:
            problems.append(
                (("placement", key), f"expected [min, max] with min ≤ max, got {show([low, high])}")
            )
    low, high = reach
    if not 0.0 <= low <= high:
        problems.append(
            (
                ("placement", "reach"),
                f"expected [min, max] distances with 0 ≤ min ≤ max, m, got {show([low, high])}",
            )
        )
    if placement.example is not None:
        outside = [
            (
                ("placement", "example", i),
                f"expected {key} within placement.{key} {show(list(ranges[key]))}, "
                f"got {show(value)}",
            )
            for i, (key, value) in enumerate(zip(PLACEMENT_KEYS, placement.example, strict=True))
            if not ranges[key][0] <= value <= ranges[key][1]
        ]
        problems.extend(outside)
        distance = math.dist(placement.example[:3], (0.0, 0.0, 0.0))
        if not outside and not low <= distance <= high:
            problems.append(
                (
                    ("placement", "example"),
                    f"expected a distance from the base origin within placement.reach "
                    f"{show(list(reach))}, got {distance:.6g} m",
                )
            )
    return problems


def _payload_problems(payload: PayloadModel | None, robot: Robot) -> list[Problem]:
    """A case's payload: physical, and on a robot with dynamics."""
    if payload is None:
        return []
    problems = payload_problems(payload, ("payload",))
    if robot.dynamics is None:
        problems.append(
            (("payload",), f"robot {robot.name} has no dynamic parameters to carry a payload")
        )
    return problems


def _objective_kind_problems(objective: ObjectiveModel, robot: Robot) -> list[Problem]:
    """``weighted`` needs a mix of known objectives; torque-based ones need dynamics."""
    problems: list[Problem] = []
    if objective.kind == "weighted":
        if not objective.mix:
            problems.append(
                (("objective", "kind"), "weighted needs objective.mix, e.g. {travel: 1, time: 0.5}")
            )
        for name in objective.mix or {}:
            if name not in OBJECTIVE_KINDS:
                problems.append(
                    (
                        ("objective", "mix", name),
                        f"unknown objective {name!r}: use {', '.join(OBJECTIVE_KINDS)}",
                    )
                )
    elif objective.mix is not None:
        problems.append((("objective", "mix"), "mix is only used with kind: weighted"))
    if not problems and robot.dynamics is None:
        names = (objective.mix or {}) if objective.kind == "weighted" else [objective.kind]
        for name in names:
            if OBJECTIVE_KINDS[name]:
                problems.append(
                    (
                        ("objective", "kind"),
                        f"{name} needs joint torques, but robot {robot.name} has no dynamic "
                        "parameters (docs/dynamics.md)",
                    )
                )
                break
    return problems


def _objective_problems(objective: ObjectiveModel, robot: Robot) -> list[Problem]:
    if objective.weights is None or len(objective.weights) == robot.n_dof:
        return []
    return [
        (
            ("objective", "weights"),
            f"expected {robot.n_dof} weights (one per joint of {robot.name}), "
            f"got {len(objective.weights)}: {show(objective.weights)}",
        )
    ]
