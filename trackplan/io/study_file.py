"""Study files (YAML): many placement searches, the cartesian product of a few lists.

::

    name: robot-selection                  # optional; the file's name by default
    cases: [../cases/*.yaml]               # globs, relative to the study file
    robots: [puma560, ur5]                 # optional: replaces each case's robot
    seeds: [0, 1, 2]                       # optional: the cases' optimizer.seed by default
    set:                                   # optional sweeps of case keys (dotted paths)
      task.rated_speed: [0.01, 0.02]

One job per (case, robot, sweep, seed); the keys are in ``docs/studies.md``.
:func:`load_study` validates everything a batch needs before any job starts: every glob
matches, every robot and ``set`` key exists, and every job's case (with the robot and the
swept values applied) is a valid case. Each problem is one
:class:`~trackplan.errors.CaseError` naming the study file and its key.
"""

from __future__ import annotations

import copy
import difflib
import glob
import itertools
import re
import typing
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, Field

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case_data
from trackplan.io.case_schema import CaseModel
from trackplan.io.input_text import read_text
from trackplan.io.robot_file import is_robot_file
from trackplan.io.yaml_input import (
    NonEmptyStr,
    StrictModel,
    model_at,
    parse_yaml,
    show,
    validate_model,
)
from trackplan.study.jobs import Job, Study

BASE_SWEEP = "base"
"""Sweep label of the jobs of a study without ``set``."""

_UNSAFE = re.compile(r"[^A-Za-z0-9._=,+-]+")
"""Characters left out of run folder names."""


class StudyModel(StrictModel):
    """Schema of a study file."""

    name: NonEmptyStr | None = None
    cases: Annotated[list[NonEmptyStr], Field(min_length=1)]
    robots: Annotated[list[NonEmptyStr], Field(min_length=1)] | None = None
    seeds: Annotated[list[Annotated[int, Field(ge=0)]], Field(min_length=1)] | None = None
    set: dict[str, Annotated[list[Any], Field(min_length=1)]] = Field(default_factory=dict)


def load_study(file: str | Path) -> Study:
    """Read a study file and build its jobs.

    Parameters
    ----------
    file
        The YAML study file. Case globs and robot files are relative to its folder.

    Returns
    -------
    Study
        Jobs in the order cases × robots × sweeps × seeds.

    Raises
    ------
    CaseError
        The first problem: an unreadable file or bad YAML, a schema problem, a glob that
        matches no file, a ``set`` key that is not a case key, a value given twice, an
        unknown robot, or a case that is invalid as given or with the study's values
        (reported at the study's key when a study value is the cause).
    """
    source = str(file)
    model = validate_model(
        StudyModel, parse_yaml(read_text(file, what="study file"), source), source
    )
    base = Path(file).parent
    for key in model.set:
        check_set_key(key, source)
    _refuse_repeats(model, source)
    sweeps = _sweeps(model.set)
    swept = {key for key, values in model.set.items() if len(values) > 1}
    robots: list[str | None] = (
        [_robot_spec(robot, base) for robot in model.robots] if model.robots else [None]
    )
    jobs: list[Job] = []
    labels: dict[str, Path] = {}
    for case_file in _case_files(model.cases, base, source):
        label = case_file.stem
        if label in labels:
            raise CaseError(
                f"two case files named {label!r} ({labels[label]} and {case_file}): their run "
                "folders would clash; rename one",
                file=source,
                key="cases",
            )
        labels[label] = case_file
        raw = parse_yaml(read_text(case_file, what="case file"), str(case_file))
        names: dict[str, int] = {}
        for index, robot in enumerate(robots):
            cases = [_job_case(raw, case_file, robot, index, sweep, source) for sweep in sweeps]
            name = cases[0].robot.name
            if robot is not None and name in names:
                raise CaseError(
                    f"robot {name!r} comes twice (robots[{names[name]}] loads it too)",
                    file=source,
                    key=f"robots[{index}]",
                )
            names[name] = index
            for sweep, case in zip(sweeps, cases, strict=True):
                for seed in model.seeds or [case.optimizer.seed]:
                    jobs.append(_job(label, case_file, case, sweep, seed, swept))
    return Study(
        name=model.name or Path(file).stem,
        jobs=tuple(jobs),
        cases=tuple(labels),
        robots=tuple(dict.fromkeys(job.robot for job in jobs)),
        source=source,
    )


def check_set_key(key: str, file: str | None = None) -> None:
    """Refuse a ``set`` key that is not a case key (dotted path of mappings).

    Raises
    ------
    CaseError
        Naming the first part that is not a key, with the keys allowed there.
    """
    where = f"set.{key}"
    if key == "robot":
        raise CaseError("set the robot with the study's robots list", file=file, key=where)
    parts = key.split(".")
    for depth, part in enumerate(parts):
        parent = model_at(CaseModel, parts[:depth])
        if parent is None or typing.get_origin(_annotation(parts[:depth])) is list:
            inside = ".".join(parts[:depth])
            raise CaseError(
                f"not a case key: {inside} holds a value, not a mapping of keys",
                file=file,
                key=where,
            )
        if part not in parent.model_fields:
            allowed = list(parent.model_fields)
            close = difflib.get_close_matches(part, allowed, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            inside = ".".join(parts[:depth]) or "a case file"
            raise CaseError(
                f"not a case key: {inside} has no key {part!r}; {hint}"
                f"expected one of: {', '.join(allowed)}",
                file=file,
                key=where,
            )


def _annotation(parts: list[str]) -> Any:
    """The annotation of the case field at a dotted path (None for the top level)."""
    if not parts:
        return None
    parent: type[BaseModel] | None = model_at(CaseModel, parts[:-1])
    return None if parent is None else parent.model_fields[parts[-1]].annotation


def _case_files(patterns: list[str], base: Path, source: str) -> list[Path]:
    """The files the globs match, in order, each once."""
    files: dict[Path, None] = {}
    for index, pattern in enumerate(patterns):
        matches = sorted(glob.glob(str(base / pattern), recursive=True))
        if not matches:
            raise CaseError(
                f"{pattern!r} matches no file (globs are relative to the study file's folder "
                f"{str(base) or '.'})",
                file=source,
                key=f"cases[{index}]",
            )
        files.update((Path(match), None) for match in matches)
    return list(files)


def _robot_spec(robot: str, base: Path) -> str:
    """A robot name, or a robot file's path relative to the study file made absolute."""
    if not is_robot_file(robot):
        return robot
    return str((base / robot).resolve())


Sweep = tuple[tuple[str, int, Any], ...]
"""One combination of swept values: (dotted key, index in its list, value) per key."""


def _sweeps(values: dict[str, list[Any]]) -> list[Sweep]:
    """The cartesian product of the ``set`` lists (one empty sweep without ``set``)."""
    per_key = [[(key, i, value) for i, value in enumerate(items)] for key, items in values.items()]
    return [tuple(combination) for combination in itertools.product(*per_key)]


def _refuse_repeats(model: StudyModel, source: str) -> None:
    """Refuse a seed or a swept value given twice (two jobs would be the same)."""
    lists: list[tuple[str, list[Any]]] = [("seeds", model.seeds or [])]
    lists += [(f"set.{key}", items) for key, items in model.set.items()]
    for key, items in lists:
        for index, value in enumerate(items):
            if value in items[:index]:
                raise CaseError(f"{show(value)} is given twice", file=source, key=f"{key}[{index}]")


def _job_case(
    raw: Any, case_file: Path, robot: str | None, robot_index: int, sweep: Sweep, source: str
) -> Case:
    """The case of one job: the case file's data with the robot and the sweep applied."""
    data = copy.deepcopy(raw)
    if isinstance(data, dict):
        if robot is not None:
            data["robot"] = robot
        for key, _, value in sweep:
            _assign(data, key.split("."), value)
    try:
        return load_case_data(data, str(case_file), case_file.parent)
    except CaseError as exc:
        raise _blame_study(exc, str(case_file), robot, robot_index, sweep, source) from None


def _assign(data: dict[str, Any], parts: list[str], value: Any) -> None:
    """Set ``data[a][b]... = value``, creating missing mappings on the way."""
    for part in parts[:-1]:
        inner = data.get(part)
        if not isinstance(inner, dict):
            inner = data[part] = {}
        data = inner
    data[parts[-1]] = copy.deepcopy(value)


def _blame_study(
    exc: CaseError, case_file: str, robot: str | None, robot_index: int, sweep: Sweep, source: str
) -> CaseError:
    """The case's error, moved to the study's key when a study value caused it."""
    if exc.file == case_file and exc.key == "robot" and robot is not None:
        return CaseError(exc.message, file=source, key=f"robots[{robot_index}]")
    for key, index, value in sweep:
        if exc.file == case_file and exc.key is not None and _within(exc.key, key):
            return CaseError(
                f"{exc.message} (the value {show(value)} set in {case_file})",
                file=source,
                key=f"set.{key}[{index}]",
            )
    return exc


def _within(found: str, key: str) -> bool:
    """True when the key path ``found`` is ``key`` or inside it."""
    return found == key or found.startswith((f"{key}.", f"{key}["))


def _job(label: str, case_file: Path, case: Case, sweep: Sweep, seed: int, swept: set[str]) -> Job:
    """One job; its sweep label names the keys given more than one value (``swept``)."""
    pairs = tuple((key, value) for key, _, value in sweep)
    sweep_label = (
        ",".join(f"{key}={_text(value)}" for key, value in pairs if key in swept) or BASE_SWEEP
    )
    robot = case.robot.name
    return Job(
        key=_UNSAFE.sub("-", f"{label}__{robot}__{sweep_label}__s{seed}"),
        case_label=label,
        case_file=str(case_file),
        robot=robot,
        sweep=pairs,
        sweep_label=sweep_label,
        seed=int(seed),
        case=case,
    )


def _text(value: Any) -> str:
    """A swept value as it appears in labels: numbers as written, lists joined by ``+``."""
    if isinstance(value, list | tuple):
        return "+".join(_text(item) for item in value)
    return show(value, limit=40).strip("'")
