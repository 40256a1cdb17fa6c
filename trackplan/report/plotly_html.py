"""A plotly figure given as plain data, written as an HTML div that works offline.

The same markup as :func:`plotly.io.to_html` with ``full_html=False`` (plotly.js embedded,
``Plotly.newPlot`` then ``Plotly.addFrames``), without its cost: ``to_html`` validates the
figure into plotly objects, walks it for numpy arrays and encodes its JSON twice, which took
longer than drawing a plot for the animated 3D view. Here the data are already JSON-ready
(lists, dicts, numbers, ``None`` for gaps) and are encoded once.

The animation frames stay off the path to the first picture: they are written as a JSON
``<script type="application/json">`` element after the drawing script (the browser does not
execute it) and parsed and added only once the figure is drawn and the page is parsed, so
that opening the page costs the parsing of the first frame's data alone. The moment the
figure is first drawn is marked ``performance.mark("<div id> drawn")``.
"""

from __future__ import annotations

import json
import pkgutil
from collections.abc import Mapping
from functools import cache

TEMPLATE = "plotly"
"""The plotly template every figure gets (plotly's own default), whatever the session's
default is, so that a report looks the same wherever it is written."""


@cache
def _template() -> dict:
    """The layout template as plotly ships it (the JSON that ``plotly.io.templates`` loads,
    read without building and validating its objects)."""
    data = pkgutil.get_data("plotly", f"package_data/templates/{TEMPLATE}.json")
    if data is None:
        raise FileNotFoundError(f"plotly's {TEMPLATE!r} template is missing")
    return dict(json.loads(data))


def _json(value: object) -> str:
    """Compact JSON that can sit inside a ``<script>`` element."""
    return json.dumps(value, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")


def plotly_div(
    figure: Mapping[str, object],
    div_id: str,
    *,
    config: Mapping[str, object] | None = None,
    post_script: str = "",
    include_plotlyjs: bool = True,
) -> str:
    """An HTML div drawing ``figure`` with plotly.js, embedded in the page (no network).

    Parameters
    ----------
    figure
        ``{"data": [trace, ...], "layout": {...}, "frames": [...]}`` with JSON-ready values
        (no NaN: gaps are ``None``); ``frames`` is optional. The layout gets plotly's
        default template unless it has one.
    div_id
        The id of the div the figure is drawn into.
    config
        plotly.js config (``responsive`` is on unless set).
    post_script
        JavaScript run once the figure and its frames are in place.
    include_plotlyjs
        Embed plotly.js (once per page: pass False for the page's further figures).

    Returns
    -------
    str
        The div, its scripts included.

    Raises
    ------
    ValueError
        When a value is not JSON (NaN or infinity included).
    """
    layout = dict(figure.get("layout") or {})  # type: ignore[call-overload]
    layout.setdefault("template", _template())
    height = layout.get("height")
    config = {"responsive": True, **(config or {})}
    script = f"Plotly.newPlot({_json(div_id)},{_json(figure.get('data', []))},{_json(layout)},"
    script += f"{_json(config)})"
    script += f".then(function(){{performance.mark({_json(div_id + ' drawn')});}})"
    frames = figure.get("frames")
    frames_element = ""
    if frames:
        frames_id = frames_element_id(div_id)
        frames_element = (
            f'<script type="application/json" id="{frames_id}">{_json(frames)}</script>'
        )
        script += f".then(function(){{return {_ADD_FRAMES}({_json(div_id)},{_json(frames_id)});}})"
    if post_script:
        script += f".then(function(){{{post_script}}})"
    library = ""
    if include_plotlyjs:
        from plotly.offline import get_plotlyjs

        library = (
            "<script>window.PlotlyConfig = {MathJaxConfig: 'local'};</script>"
            f'<script charset="utf-8">{get_plotlyjs()}</script>'
        )
    size = f"height:{height}px; width:100%;" if height else "height:100%; width:100%;"
    return (
        f'<div style="{size}">{library}'
        f'<div id="{div_id}" class="plotly-graph-div" style="height:100%; width:100%;"></div>'
        f"<script>window.PLOTLYENV=window.PLOTLYENV || {{}};"
        f"if (document.getElementById({_json(div_id)})) {{{script};}}</script>"
        f"{frames_element}</div>"
    )


def frames_element_id(div_id: str) -> str:
    """The id of the JSON element holding the animation frames of the figure in ``div_id``."""
    return f"{div_id}-frames"


_ADD_FRAMES = (
    "(function(id,framesId){return new Promise(function(done){"
    "var add=function(){var element=document.getElementById(framesId);"
    "done(Plotly.addFrames(id,JSON.parse(element.textContent)));};"
    "if(document.readyState==='loading'){document.addEventListener('DOMContentLoaded',add);}"
    "else{add();}});})"
)
"""JavaScript: add the frames of the JSON element once the page is parsed (the element
follows the drawing script, so it may not be parsed yet when the figure is drawn)."""
