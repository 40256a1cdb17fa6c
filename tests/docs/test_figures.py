"""Figures the topic pages state are recomputed here, so the pages cannot go stale."""

from __future__ import annotations

import numpy as np

from tests.docs import console
from trackplan.paths import (
    LineSpec,
    NominalPath,
    build_path,
    corrected_corner_radius,
    paper_corner_angle,
    paper_corner_radius,
)


def _text(page: str) -> str:
    return " ".join((console.REPO / "docs" / page).read_text(encoding="utf-8").split())


def test_paths_page_paper_corner_table():
    """docs/paths.md, "The paper's corner"."""
    text = _text("paths.md")
    a, b, c = np.zeros(3), np.array([0.5, 0.0, 0.0]), np.array([0.3, 0.0, 0.5])
    rho = 1e-3
    beta = paper_corner_angle(a, b, c)
    assert f"β = {np.degrees(beta):.3f}°" in text
    assert f"turns by {180 - np.degrees(beta):.3f}°" in text
    r_paper, r_fixed = paper_corner_radius(beta, rho), corrected_corner_radius(beta, rho)
    assert f"r = {r_paper * 1e3:.3f} mm" in text and f"r = {r_fixed * 1e3:.3f} mm" in text
    assert f"{1 / r_paper:.1f} 1/m" in text and f"{1 / r_fixed:.1f} 1/m" in text
    nominal = NominalPath.from_specs(a, (LineSpec(b), LineSpec(c)))
    planned = build_path(nominal, rho)
    blend = next(piece for piece in planned.pieces if piece.kind == "blend")
    s = np.linspace(blend.s_start, blend.s_start + blend.length, 20001)
    peak = np.linalg.norm(planned.sample(s).curvature, axis=1).max()
    assert f"blend {blend.length * 1e3:.3f} mm" in text
    assert f"**{peak:.1f} 1/m**" in text
    assert f"{planned.length:.5f} m long (nominal {nominal.length:.5f} m)" in text
    arc = next(p for p in build_path(nominal, rho, mode="paper").pieces if p.kind == "arc")
    assert f"arc {arc.length * 1e3:.3f} mm" in text
