// Sent with plotly.js by app/ui/plotly_js.py: wraps Plotly.react, which viser's plot widget calls
// with each figure (and again on every change of its box's width or of the widget's aspect).
(() => { const P = window.Plotly; if (!P || P.__appSized) return; P.__appSized = true; const react = P.react;
  // The height of a figure with layout.meta.fit_height = [chrome, least, most]: the window's height
  // less chrome [px], within [least, most] × its width.
  const fitted = (layout) => {
    const fit = layout.meta && layout.meta.fit_height;
    if (!Array.isArray(fit)) return layout;
    const [chrome, least, most] = fit;
    const h = Math.min(most * layout.width, Math.max(least * layout.width, window.innerHeight - chrome));
    return {...layout, height: Math.round(h)};
  };
  // The same figure again: the same data and config objects and a layout whose entries are the same
  // objects or values (viser copies the parsed layout's entries; Plotly changes them in place).
  const same = (gd, data, layout, config) => {
    const last = gd.__appLast, keys = Object.keys(layout);
    return !!last && last.data === data && last.config === config && last.keys.length === keys.length
      && keys.every(k => last.layout[k] === layout[k]);
  };
  // Draw now; once the browser has painted it (the task after the next frame), the figure waiting, if any.
  const draw = (gd, args) => {
    gd.__appPainted = false;
    requestAnimationFrame(() => setTimeout(() => {
      gd.__appPainted = true; const next = gd.__appNext; gd.__appNext = null; if (next) next(); }, 0));
    return react.apply(P, args);
  };
  P.react = function (gd, data, layout, ...rest) {
    if (!(layout && typeof layout === 'object')) return react.call(this, gd, data, layout, ...rest);
    if (layout.width === 0) return Promise.resolve(gd);  // a box not measured yet (or hidden)
    layout = fitted(layout);
    if (same(gd, data, layout, rest[0])) return Promise.resolve(gd);  // Plotly would still take ≈ 0.1 s
    gd.__appLast = {data, config: rest[0], layout: {...layout}, keys: Object.keys(layout)};
    const args = [gd, data, layout, ...rest];
    // A figure waits while the last one is not painted yet (each figure drawn is seen: the light
    // overview before the one with its replay), and a slider's for the next frame, after the input
    // waiting; of the figures waiting only the latest is drawn.
    const waits = gd.__appPainted === false || !!(rest[0] && rest[0].staticPlot);
    if (!waits) { gd.__appNext = null; return draw(gd, args); }
    return new Promise(done => {
      const run = () => done(draw(gd, args));
      gd.__appNext = run;
      if (gd.__appPainted !== false) {
        requestAnimationFrame(() => { if (gd.__appNext === run) { gd.__appNext = null; run(); } });
      }
    });
  }; })();
