// Installed once per page by app/ui/demo_view.py (UUID, MODE_TABS and RESULTS_TABS filled in there).
// Writes what the page shows — the selected mode and results tabs, the overview's zoomed axes — as
// JSON into the hidden text field UUID, as if typed (so viser sends it), whenever it may have changed:
// after a click or key press (a tab chosen) and after the overview's axes changed (plotly_relayout).
// The zoom of an overview element starts from its figure's layout.meta.zoom (a restored zoom) at each
// new figure (plotly_react). A results tab left and chosen again mounts a new overview element (viser
// unmounts hidden tabs): the zoom of the same figure is kept across that (window.__appZoomKept) and
// put back with Plotly.relayout. Reads Plotly's el.layout (the ranges as drawn), a public property.
(() => {
  const uuid = UUID, modeTabs = MODE_TABS, resultsTabs = RESULTS_TABS;
  const H = PAGE_HOOKS;  // viser's markup this script hooks into (app/ui/page_hooks.py)
  const setValue = Object.getOwnPropertyDescriptor(HTMLInputElement.prototype, 'value').set;
  const axisKey = /^([xy]axis[2-9]?)\.(range|autorange)/;
  const overview = () => [...document.querySelectorAll('.js-plotly-plot')]
    .find(e => e.layout && e.layout.meta && e.layout.meta.id === 'phase_plane');
  const selected = (titles) => {
    const tab = [...document.querySelectorAll(H.SELECTED_TAB.sel)]
      .find(t => titles.includes(t.getAttribute(H.TAB.attr)));
    return tab ? tab.getAttribute(H.TAB.attr) : null;
  };
  const restart = (el) => { el.__appZoom = Object.assign({}, (el.layout.meta || {}).zoom || {}); };
  // The figure an element shows: its title and meta (ω_p, T_c …); a new run gives a new one.
  const figureKey = (el) => JSON.stringify([el.layout.title, el.layout.meta]);
  const keep = (el) => { window.__appZoomKept = {key: figureKey(el), zoom: Object.assign({}, el.__appZoom)}; };
  const putBack = (el) => {
    const kept = window.__appZoomKept;
    if (!kept || kept.key !== figureKey(el) || Object.keys(el.__appZoom).length) return;
    const update = {};
    for (const [axis, range] of Object.entries(kept.zoom)) update[axis + '.range'] = range;
    if (Object.keys(update).length) window.Plotly.relayout(el, update);
  };
  const hook = (el) => {
    if (el.__appViewHooked || !el.on || !el._fullLayout) return;
    el.__appViewHooked = true;
    restart(el);
    putBack(el);
    el.on('plotly_react', () => { restart(el); keep(el); report(); });
    el.on('plotly_relayout', (ev) => {
      for (const key of Object.keys(ev || {})) {
        const m = key.match(axisKey);
        if (!m) continue;
        const axis = el.layout[m[1]];
        if (m[2] === 'autorange' && ev[key]) delete el.__appZoom[m[1]];
        else if (axis && Array.isArray(axis.range)) el.__appZoom[m[1]] = [Number(axis.range[0]), Number(axis.range[1])];
      }
      keep(el);
      report();
    });
  };
  let frame = 0;
  const report = () => {
    const label = [...document.querySelectorAll(H.FIELD_LABEL.sel)]
      .find(l => l.getAttribute(H.FIELD_LABEL.attr) === uuid);
    const flex = label && label.closest(H.FIELD_ROW.sel);
    const input = flex && flex.querySelector('input');
    if (!input) {  // not mounted yet: look again next frame (for at most ≈ 1 min)
      if (++frame < 3600) requestAnimationFrame(report);
      return;
    }
    frame = 0;
    const el = overview();
    if (el) hook(el);
    const view = JSON.stringify({tab: {mode: selected(modeTabs), results: selected(resultsTabs)},
                                 zoom: (el && el.__appZoom) || {}});
    if (input.value === view) return;
    setValue.call(input, view);
    input.dispatchEvent(new Event('input', {bubbles: true}));
  };
  // after the tab strip took the click or key; a newly shown overview is drawn a few frames later:
  // one watch at a time, for at most 120 frames, ended by an overview hooked
  let watchFrames = 0;
  const watchMount = () => {
    const el = overview();
    if (el && el._fullLayout) { if (!el.__appViewHooked) { hook(el); report(); } watchFrames = 0; return; }
    if (watchFrames > 0) { watchFrames -= 1; requestAnimationFrame(watchMount); }
  };
  const later = () => {
    setTimeout(report, 60);
    const idle = watchFrames === 0;
    watchFrames = 120;
    if (idle) watchMount();
  };
  if (window.__appPageView) {
    for (const [type, fn] of window.__appPageView) document.removeEventListener(type, fn, true);
  }
  // pointerdown hooks the overview before a zoom drag ends; click and keydown: a tab chosen
  window.__appPageView = [['pointerdown', () => { const el = overview(); if (el) hook(el); }],
                          ['click', later], ['keydown', later]];
  for (const [type, fn] of window.__appPageView) document.addEventListener(type, fn, true);
  report();
})();
