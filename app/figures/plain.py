"""Figure JSON without Plotly's per-trace validation: plain-dict figures, encoded once.

Building a ``go.Figure`` validates every property of every trace and deep-copies the template;
for the page's figures that is most of the server's CPU per Simulate. The figure functions
therefore describe a figure as a plain dict (``{"data": [...], "layout": {...}}``, numpy arrays
allowed) and :func:`figure_json` encodes it directly: float arrays as Plotly's base64 typed arrays
(``{"dtype": "f4", "bdata": …}``, as ``plotly.io.to_json`` writes them) and ``layout.template``
names replaced by the template's JSON, rendered once per process.
"""

from __future__ import annotations

import base64
import functools
import json
from typing import Any

import numpy as np
import plotly.graph_objects as go
import plotly.io as pio

from pmsm_commissioning.app.figures.style import FONT_PX, TEMPLATE_LAYOUT, TITLE_PX

#: Trace types whose template defaults are kept (the only ones the page draws), and the layout
#: parts of a template that cartesian 2D figures never use (polar, ternary, 3D scene, geo, …).
_TEMPLATE_TRACES = ("scatter", "bar")
_UNUSED_LAYOUT = ("polar", "ternary", "scene", "geo", "mapbox", "map", "coloraxis", "colorscale", "shapedefaults",
                  "annotationdefaults", "autotypenumbers")


@functools.cache
def template_json(name: str) -> str:
    """JSON of a named Plotly template (e.g. ``"plotly_white"``) cut to what the page's figures use, rendered once.

    The full template (≈7 kB) sets defaults for some 40 trace types and for polar, ternary, 3D and
    geo axes; each figure carries its template, so only the scatter and bar defaults and the
    layout of cartesian axes, colours and fonts are kept (≈1.5 kB): the figures look the same.
    """
    full = pio.templates[name].to_plotly_json()
    slim = {"data": {k: v for k, v in full.get("data", {}).items() if k in _TEMPLATE_TRACES},
            "layout": {k: v for k, v in full.get("layout", {}).items() if k not in _UNUSED_LAYOUT}}
    for axis in ("xaxis", "yaxis"):
        # Plotly's default ("hide past div") measures every tick label for each redraw (≈ 6 % of an
        # overview redraw in headless Chromium); the figures' margins keep the labels inside anyway
        old = slim["layout"].get(axis, {})
        slim["layout"][axis] = {**old, "ticklabeloverflow": "allow", "tickfont": {"size": FONT_PX},
                                "title": {**old.get("title", {}), "font": {"size": FONT_PX}}}
    for key, value in TEMPLATE_LAYOUT.items():  # the page's font sizes (app.figures.style)
        slim["layout"][key] = {**slim["layout"].get(key, {}), **value}
    return json.dumps(slim, separators=(",", ":"))


@functools.lru_cache(maxsize=64)
def placeholder_json(figure_id: str, title: str, height: float = 260.0) -> str:
    """JSON of an empty figure titled ``title`` (``layout.meta.id`` = ``figure_id``), until results arrive."""
    return figure_json({"data": [], "layout": {
        "meta": {"id": figure_id}, "title": {"text": title, "font": {"size": TITLE_PX}}, "height": height,
        "template": "plotly_white", "margin": {"l": 40, "r": 10, "t": 40, "b": 30}}})


@functools.cache
def slim_template(name: str = "plotly_white") -> go.layout.Template:
    """Return the cut template of :func:`template_json` as a ``go.layout.Template`` (for ``go.Figure``)."""
    return go.layout.Template(json.loads(template_json(name)))


@functools.cache
def blank_json() -> str:
    """Return the JSON of an empty figure with the slim template (a placeholder until results arrive).

    ``go.Figure()`` carries Plotly's full default template, ≈ 7 kB per placeholder at page open.
    """
    return figure_json({"data": [], "layout": {"template": "plotly_white"}})


def _default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "f":
            a = np.ascontiguousarray(obj, dtype=np.float32 if obj.dtype.itemsize <= 4 else np.float64)
            return {"dtype": "f4" if a.itemsize == 4 else "f8", "bdata": base64.b64encode(a).decode("ascii")}
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


_TEMPLATE_MARK = '"__template__"'


def figure_json(spec: dict[str, Any], raw: dict[str, str] | None = None) -> str:
    """Return the Plotly JSON of a plain-dict figure ``spec`` (not modified).

    ``raw`` maps placeholder strings used as values in ``spec`` to ready-made JSON put in their place.
    """
    layout = dict(spec.get("layout", {}))
    name = layout.get("template")
    if isinstance(name, str):
        layout["template"] = "__template__"
    text = json.dumps({**spec, "layout": layout}, default=_default, separators=(",", ":"))
    for mark, value in (raw or {}).items():
        text = text.replace(f'"{mark}"', value, 1)
    return text.replace(_TEMPLATE_MARK, template_json(name), 1) if isinstance(name, str) else text


def to_figure(spec: dict[str, Any]) -> go.Figure:
    """Return a validated ``go.Figure`` of a plain-dict figure (for exports and tests; slower)."""
    return go.Figure(spec)


__all__ = ["blank_json", "figure_json", "placeholder_json", "slim_template", "template_json", "to_figure"]
