"""map.html: the placement map in the report's look."""

from __future__ import annotations

import re

import numpy as np

from trackplan.report.cell_figures import write_map_report
from trackplan.report.html import report_page
from trackplan.search.placement_map import REASONS, PlacementMap

STYLE = re.compile(r"<style>(.*?)</style>", re.DOTALL)


def _map() -> PlacementMap:
    x, y = np.linspace(0.1, 0.7, 5), np.linspace(-0.5, 0.5, 4)
    reason = np.arange(20).reshape(4, 5) % len(REASONS)
    objective = np.where(
        reason == REASONS.index("feasible"), 0.5 + 0.01 * np.arange(20).reshape(4, 5), np.nan
    )
    return PlacementMap(
        case_name="bracket-weld",
        x=x,
        y=y,
        z=-0.28,
        rpy=np.array([0.3, 0.05, -2.5]),
        reason=reason,
        objective=objective,
        reference=np.array([0.36, -0.35, -0.28, 0.3, 0.05, -2.5]),
    )


def test_map_page_has_the_report_style_and_layout(tmp_path, corner, corner_result):
    """map.html was a bare page (browser default font, a run-on sentence of figures): it
    has the report's style sheet, the same one (shared, not copied), a heading, the map's
    figures in tables with named columns and units, and the plot as a captioned figure."""
    pmap = _map()
    write_map_report(pmap, tmp_path)
    page = (tmp_path / "map.html").read_text(encoding="utf-8")
    report = report_page(corner_result, corner, [], "")
    (style,) = STYLE.findall(page)
    assert style == STYLE.findall(report)[0]
    assert '<meta name="viewport"' in page
    assert "<h1>Placement map: bracket-weld</h1>" in page
    assert re.search(
        r'<figure id="plot-map">.*<img[^>]*src="data:image/png;base64,.*<figcaption>',
        page,
        re.DOTALL,
    )
    headers = re.findall(r"<th(?:\s[^>]*)?>(.*?)</th>", page)
    for name in ("grid", "z [m]", "roll [rad]", "pitch [rad]", "yaw [rad]", "least J"):
        assert name in headers, name
    for reason in REASONS:
        assert reason in headers, reason
    shares = {r: f"{100 * np.mean(pmap.reason == k):.0f} %" for k, r in enumerate(REASONS)}
    for reason, share in shares.items():
        assert f">{share}<" in page, (reason, share)
