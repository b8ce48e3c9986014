"""The page's wrapper of ``Plotly.react`` (app/ui/assets/plotly_react.js) in Chromium, on a bare page.

What viser's plot widget calls it with: a box not measured yet (width 0), the same figure again
(a new aspect), a window-fitted figure, and a slider's static figures arriving faster than drawn.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from pmsm_commissioning.app.ui.layout import ASPECT_MAX, ASPECT_MIN, CHROME_HEIGHT
from pmsm_commissioning.app.ui.plotly_js import REACT_JS, bundle_source

#: A plot, its data, layout and config as viser holds them (parsed once per figure).
SETUP = """() => { window.draws = 0; window.gd = document.getElementById('p');
  window.data = [{type: 'scatter', x: [0, 1, 2], y: [0, 1, 0], name: 'a'}];
  window.config = {};
  window.layout = {xaxis: {range: [0, 2]}, yaxis: {range: [0, 1]}, margin: {l: 40, r: 10, t: 10, b: 30}}; }"""

#: Draws counted by Plotly's own event.
COUNT = "() => { window.gd.on('plotly_afterplot', () => { window.draws += 1; }); }"


@pytest.fixture
def bare(browser: Any) -> Iterator[Any]:
    context = browser.new_context(viewport={"width": 1000, "height": 700})
    page = context.new_page()
    page.set_content("<div id='p'></div>")
    page.add_script_tag(content=bundle_source() + "\n" + REACT_JS)
    page.evaluate(SETUP)
    yield page
    context.close()


def _react(page: Any, layout_js: str, config_js: str = "window.config") -> None:
    page.evaluate(f"() => Plotly.react(window.gd, window.data, {layout_js}, {config_js})")


def test_a_box_of_width_0_draws_nothing_and_the_same_figure_again_draws_nothing(bare):
    _react(bare, "{...window.layout, width: 0, height: 0}")
    assert bare.evaluate("() => !window.gd._fullLayout")  # Plotly never drew into the unmeasured box
    _react(bare, "{...window.layout, width: 600, height: 300}")
    bare.evaluate(COUNT)
    assert bare.evaluate("() => window.gd._fullLayout.width") == 600
    _react(bare, "{...window.layout, width: 600, height: 300}")  # viser's copy of the same layout entries
    bare.wait_for_timeout(100)
    assert bare.evaluate("() => window.draws") == 0
    _react(bare, "{...window.layout, width: 500, height: 300}")  # a new width is drawn
    bare.wait_for_function("() => window.gd._fullLayout.width === 500")


def test_a_window_fitted_figure_is_as_tall_as_the_window_allows(bare):
    fit = f"[{CHROME_HEIGHT}, {ASPECT_MIN}, {ASPECT_MAX}]"
    _react(bare, f"{{...window.layout, width: 800, height: 100, meta: {{fit_height: {fit}}}}}")
    assert bare.evaluate("() => window.gd._fullLayout.height") == round(700 - CHROME_HEIGHT)
    _react(bare, f"{{...window.layout, width: 2000, height: 100, meta: {{fit_height: {fit}}}}}")
    assert bare.evaluate("() => window.gd._fullLayout.height") == round(ASPECT_MIN * 2000)  # least aspect


def test_a_sliders_figures_are_drawn_after_waiting_events_and_only_the_latest(bare):
    """Static figures (a slider's) are drawn at the next animation frame; one replaced before then is never drawn."""
    _react(bare, "{...window.layout, width: 600, height: 300}")
    bare.evaluate(COUNT)
    drawn = bare.evaluate("""() => { const seen = [];
      Plotly.react(window.gd, [{...window.data[0], name: 'old'}], {...window.layout, width: 600, height: 300},
                   {staticPlot: true});
      seen.push(window.gd.data[0].name);  // not drawn yet: the events waiting go first
      Plotly.react(window.gd, [{...window.data[0], name: 'new'}], {...window.layout, width: 600, height: 300},
                   {staticPlot: true});
      return new Promise(r => setTimeout(() => r([...seen, window.gd.data[0].name, window.draws]), 200)); }""")
    assert drawn == ["a", "new", 1]


def test_a_figure_waits_until_the_last_one_is_painted(bare):
    """The light overview is seen before the one with its replay: the second figure is drawn a frame later."""
    order = bare.evaluate("""() => { const seen = [];
      const fig = (name) => [{...window.data[0], name}];
      const layout = {...window.layout, width: 600, height: 300};
      Plotly.react(window.gd, fig('light'), layout, window.config);
      seen.push(window.gd.data[0].name);  // drawn at once
      Plotly.react(window.gd, fig('whole'), layout, window.config);
      seen.push(window.gd.data[0].name);  // waits for the paint of the light one
      return new Promise(r => setTimeout(() => r([...seen, window.gd.data[0].name]), 200)); }""")
    assert order == ["light", "light", "whole"]
