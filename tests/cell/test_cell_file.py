"""The ``cell:`` block of case files: shapes, meshes, and one clear line per bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from trackplan.cell.model import Shape
from trackplan.cli import ExitCode, main
from trackplan.io.case_file import load_case

REPO = Path(__file__).resolve().parents[2]
CORNER = (REPO / "cases" / "paper-corner.yaml").read_text(encoding="utf-8")


def write_case(tmp_path: Path, cell: str) -> Path:
    file = tmp_path / "cell.yaml"
    file.write_text(CORNER + "cell:\n" + cell, encoding="utf-8")
    return file


def validate(capsys: pytest.CaptureFixture[str], file: Path) -> tuple[int, str]:
    code = main(["validate", str(file)])
    return code, capsys.readouterr().err.strip()


def test_every_shape_loads(tmp_path: Path) -> None:
    trimesh.creation.box(extents=(100.0, 200.0, 300.0)).export(tmp_path / "block.stl")
    file = write_case(
        tmp_path,
        """
  clearance: 0.02
  obstacles:
    - {name: floor, plane: {normal: [0, 0, 2], offset: -1.3}}
    - {name: table, box: {size: [1.2, 0.8, 0.04], pose: [0.7, 0, -0.42, 0, 0, 0]}}
    - {name: column, cylinder: {radius: 0.06, length: 1.5, pose: [-0.4, 0.5, 0.1, 0, 0, 0]}}
    - {name: ball, sphere: {radius: 0.1, pose: [0.5, 0.5, 0.5, 0, 0, 0]}}
    - {name: post, capsule: {radius: 0.05, length: 0.4, pose: [0, 0.6, 0, 0, 0, 0]}}
    - {name: block, mesh: {file: block.stl, pose: [1, 0, 0, 0, 0, 0], scale: 0.001}}
  workpiece:
    - {name: plate, box: {size: [0.6, 0.3, 0.01], pose: [0.25, 0.1, -0.005, 0, 0, 0]}}
  tool:
    - {name: torch, from: [0, 0, -0.2], to: [0, 0, 0], radius: 0.015}
  tool_contact: 0.02
""",
    )
    cell = load_case(file).cell
    assert cell is not None
    assert [b.shape for b in cell.obstacles] == [
        Shape.PLANE,
        Shape.BOX,
        Shape.CYLINDER,
        Shape.SPHERE,
        Shape.CAPSULE,
        Shape.MESH,
    ]
    floor, table, column, _, _, block = cell.obstacles
    np.testing.assert_allclose(floor.T_frame_body[:3, 2], [0, 0, 1])  # unit normal
    np.testing.assert_allclose(floor.T_frame_body[2, 3], -0.65)  # offset / |normal|
    np.testing.assert_allclose(table.size, [0.6, 0.4, 0.02])  # half extents
    np.testing.assert_allclose(column.size[:2], [0.06, 0.75])
    T_box, half = block.screening_box()  # scaled to metres
    np.testing.assert_allclose(half, [0.05, 0.1, 0.15], atol=1e-12)
    np.testing.assert_allclose(T_box[:3, 3], [1, 0, 0], atol=1e-12)
    assert cell.workpiece[0].name == "plate"
    assert cell.tool.name == ("torch",) and cell.tool_contact == 0.02 and cell.clearance == 0.02


@pytest.mark.parametrize(
    ("cell", "message"),
    [
        (
            "  obstacles:\n    - {name: fence, mesh: {file: fence.stl}}\n",
            "cell.obstacles[0].mesh.file: mesh file '{dir}/fence.stl' not found",
        ),
        (
            "  workpiece:\n    - {name: part, mesh: {file: broken.stl}}\n",
            "cell.workpiece[0].mesh.file: mesh file '{dir}/broken.stl' cannot be read as a mesh",
        ),
        (
            "  obstacles:\n    - {name: t, box: {size: [1, 0, 1]}}\n",
            "cell.obstacles[0].box.size[1]: expected a number > 0, got 0",
        ),
        (
            "  obstacles:\n    - {name: c, cone: {radius: 1}}\n",
            "cell.obstacles[0].cone: unknown key; expected one of: name, plane, box, cylinder,"
            " sphere, capsule, mesh",
        ),
        (
            "  obstacles:\n    - {name: floor, plane: {normal: [0, 0, 0], offset: 0}}\n",
            "cell.obstacles[0].plane.normal: expected a non-zero normal vector, "
            "got [0.0, 0.0, 0.0]",
        ),
        ("  tool_contact: -0.01\n", "cell.tool_contact: expected a number ≥ 0, got -0.01"),
        (
            "  obstacles:\n    - {name: m, mesh: {file: tri.stl, scale: 1.0e+300}}\n",
            "cell.obstacles[0].mesh.scale: mesh file '{dir}/tri.stl' has a vertex 1e+299 m from"
            " its origin once scaled: vertices must lie within ±1000 m",
        ),
        (
            "  obstacles:\n    - {name: m, mesh: {file: /dev/zero}}\n",
            "cell.obstacles[0].mesh.file: mesh file '/dev/zero' is a character device, not a"
            " regular file",
        ),
        (
            "  obstacles:\n    - {name: m, mesh: {file: sub}}\n",
            "cell.obstacles[0].mesh.file: mesh file '{dir}/sub' is a directory, not a regular file",
        ),
    ],
    ids=[
        "missing-mesh",
        "unreadable-mesh",
        "box-size",
        "unknown-shape",
        "zero-normal",
        "contact",
        "mesh-scale-1e300",
        "mesh-dev-zero",
        "mesh-directory",
    ],
)
def test_bad_cell_is_one_line_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, cell: str, message: str
) -> None:
    (tmp_path / "broken.stl").write_bytes(b"solid x\nthis is not an stl file\n")
    trimesh.Trimesh([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], [[0, 1, 2]]).export(tmp_path / "tri.stl")
    (tmp_path / "sub").mkdir()
    file = write_case(tmp_path, cell)
    code, err = validate(capsys, file)
    assert code == ExitCode.BAD_INPUT
    assert len(err.splitlines()) == 1
    assert err.startswith(f"{file}: " + message.format(dir=tmp_path))


def test_robot_without_link_capsules_needs_links(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robot = tmp_path / "arm.yaml"
    main(["robots", "--yaml", "puma560"])
    text = capsys.readouterr().out.replace("name: puma560", "name: arm")
    robot.write_text(text.split("\ncollision:")[0] + "\n", "utf-8")
    file = tmp_path / "cell.yaml"
    text = CORNER.replace("robot: puma560", "robot: arm.yaml")
    file.write_text(text + "cell:\n  clearance: 0.01\n", encoding="utf-8")
    code, err = validate(capsys, file)
    assert code == ExitCode.BAD_INPUT
    assert err.startswith(f"{file}: cell: robot 'arm' has no link capsules")
    links = "  links:\n    - {link: 2, from: [-0.4, 0, 0], to: [0, 0, 0], radius: 0.07}\n"
    file.write_text(text + "cell:\n" + links, encoding="utf-8")
    assert load_case(file).cell.links.name == ("link 2",)
