// Installed once per page by app/ui/k_sweep.py. The K sweep figure's slider steps carry their frame
// inline (execute: false): a step chosen by the user is handed to Plotly.animate here, where the
// rejection of an animation the next step interrupts is swallowed (Plotly's own call logged it).
(() => { if (window.__appKSweep) return; window.__appKSweep = true;
  window.__appKSweepFrames = 0;
  setInterval(() => { for (const el of document.querySelectorAll('.js-plotly-plot')) {
    if (!(el.layout && el.layout.meta && el.layout.meta.id === 'k_sweep') || el.__appKSweep || !el.on) continue;
    el.__appKSweep = true;
    el.on('plotly_sliderchange', (e) => { const s = e && e.step;
      if (s && s.method === 'animate' && s.execute === false && window.Plotly) {
        window.Plotly.animate(el, ...s.args).then(() => { window.__appKSweepFrames += 1; }).catch(() => {}); } });
  } }, 250); })();
