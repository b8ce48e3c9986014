// Installed once per page by app/ui/replay.py. Reads Plotly's internal el._fullData and el._transitioning
// (no public equivalent: the trail's points as drawn, and whether a replay transition still runs), and
// draws the "Replay t" slider (app.ui.replay.Replay) at the replay's time.
(() => { if (window.__appReplayButtons) return; window.__appReplayButtons = true;
  const H = PAGE_HOOKS;  // viser's markup this script hooks into (app/ui/page_hooks.py)
  const stash = (el) => { if (el.__trailFor !== el.data) { el.__trailFor = el.data;
      el.__trail = (el._fullData || []).filter(d => d.meta && typeof d.meta.trail === 'number')
                   .map(d => [d.index, d.meta.trail, d.x, d.y]); }
    return el.__trail; };
  // a redraw while a replay's transition still runs is undone when it ends: wait for its end
  window.__appAfterTransition = (el, fn) => { const go = () => el._transitioning ? requestAnimationFrame(go) : fn();
    go(); };
  window.__appTrail = (el, t) => { const s = stash(el); if (!s.length) return;
    window.Plotly.restyle(el, {x: s.map(r => r[1] <= t ? r[2] : r[2].slice(0, 1)),
                               y: s.map(r => r[1] <= t ? r[3] : r[3].slice(0, 1))},
                          s.map(r => r[0])).catch(() => {}); };
  // the "Replay t" slider shows the replay's time: its thumb, bar and number box as drawn (viser's
  // value is not changed: a change would go to the server as a scrub and stop the replay)
  const follow = (frame) => { const text = frame && frame.data && frame.data[0] && frame.data[0].text;
    const t = text ? parseFloat(String(text[0]).replace('t = ', '')) : NaN;
    const label = [...document.querySelectorAll(H.FIELD_LABEL.sel)].find(l => l.textContent.trim() === 'Replay t [s]');
    const row = label && label.closest(H.FIELD_ROW.sel);
    const thumb = row && row.querySelector(H.SLIDER_THUMB.sel);
    if (!(thumb && isFinite(t))) return;
    const end = parseFloat(thumb.getAttribute(H.SLIDER_THUMB.attr)), p = Math.min(100, Math.max(0, 100 * t / end));
    const [offset] = H.SLIDER_THUMB.vars, [width, size] = H.SLIDER_BAR.vars;
    thumb.style.setProperty(offset, `${p}%`);
    const bar = row.querySelector(H.SLIDER_BAR.sel);
    if (bar) bar.style.setProperty(width, `calc(${p}% + 2 * var(${size}))`);
    const box = row.querySelector(H.NUMBER_INPUT.sel);
    if (box && document.activeElement !== box) box.value = t.toFixed(3); };
  setInterval(() => { for (const el of document.querySelectorAll('.js-plotly-plot')) {
    if (!(el.layout && el.layout.meta && el.layout.meta.overview && el._fullData)) continue;
    stash(el);
    if (el.__appReplayButtons || !el.on) continue;
    el.__appReplayButtons = true;
    el.on('plotly_buttonclicked', (e) => { const b = e && e.button;
      if (b && b.method === 'animate' && b.execute === false && window.Plotly) {
        stash(el); window.Plotly.animate(el, ...b.args).catch(() => {}); } });
    el.on('plotly_animatingframe', (e) => follow(e && e.frame));
  } }, 250); })();
