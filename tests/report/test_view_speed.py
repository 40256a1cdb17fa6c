"""What keeps the 3D view's first drawing fast: the animation frames are parsed and added
after it, and the frames' names are page text, not a WebGL text trace (whose glyphs
plotly.js traces into triangles when the page opens).

The browser measures the opening itself (``test_browser.py``).
"""

from __future__ import annotations

import json
import re

import numpy as np

from trackplan.frames import placement_transform
from trackplan.report.plotly_html import frames_element_id, plotly_div
from trackplan.report.robot_view import robot_view_spec

FIGURE = {
    "data": [{"type": "scatter3d", "x": [0, 1], "y": [0, 1], "z": [0, 1], "name": "line"}],
    "layout": {"height": 300},
    "frames": [
        {"name": f"frame-{k}", "data": [{"x": [k, k + 1]}], "traces": [0]} for k in range(3)
    ],
}


def _scripts(html: str) -> list[tuple[str, str]]:
    """The page's script elements in order: (attributes, text)."""
    return re.findall(r"<script([^>]*)>(.*?)</script>", html, re.DOTALL)


def test_the_frames_are_parsed_after_the_first_drawing():
    html = plotly_div(FIGURE, "view", include_plotlyjs=False, post_script="window.done = 1;")
    scripts = _scripts(html)
    drawing = next(i for i, (_, text) in enumerate(scripts) if "Plotly.newPlot" in text)
    attributes, text = scripts[drawing + 1]
    # a JSON element after the drawing script: the browser does not run it
    assert f'type="application/json" id="{frames_element_id("view")}"' in attributes
    assert json.loads(text) == FIGURE["frames"]
    code = scripts[drawing][1]
    assert "frame-1" not in code  # the drawing script carries the first picture alone
    # the frames are added once the figure is drawn (and marked), before the post script
    marked = code.index('performance.mark("view drawn")')
    added = code.index("Plotly.addFrames")
    assert code.index("Plotly.newPlot") < marked < added < code.index("window.done = 1;")


def test_a_figure_without_frames_has_no_frames_element():
    html = plotly_div({**FIGURE, "frames": []}, "view", include_plotlyjs=False)
    assert frames_element_id("view") not in html
    assert "Plotly.addFrames" not in html


def test_the_frames_names_are_scene_annotations(corner, corner_result):
    view = robot_view_spec(corner_result, corner, n_frames=4)
    assert not [t for t in view["data"] if "text" in t.get("mode", "")]
    annotations = view["layout"]["scene"]["annotations"]
    assert [a["text"] for a in annotations] == ["base frame", "part frame"]
    at = np.array([[a[axis] for axis in "xyz"] for a in annotations])
    T = placement_transform(corner_result.placement)
    np.testing.assert_allclose(at, [np.zeros(3), T[:3, 3]], atol=1e-5)
    assert all(a["showarrow"] is False for a in annotations)
