// Installed once per page by app/ui/layout.py (page_marks_js): marks the elements the page's CSS
// styles, instead of CSS :has() rules (with one in the page every forced layout re-styled it all).
(() => { if (window.__appPageMarks) return; window.__appPageMarks = true;
  const H = PAGE_HOOKS;  // viser's markup the marks hook into (app/ui/page_hooks.py)
  const hiddenFields = HIDDEN_FIELDS;  // text fields the page's scripts write into
  const root = document.documentElement;
  const flag = (el, name, on) => { if (el.hasAttribute(name) !== on) el.toggleAttribute(name, on); };
  const only = (name, want) => {  // the attribute `name` on exactly the elements of `want` (value: want's map)
    for (const el of document.querySelectorAll(`[${name}]`)) if (!want.has(el)) el.removeAttribute(name);
    for (const [el, v] of want) if (el.getAttribute(name) !== v) el.setAttribute(name, v); };
  const tabTitle = (tab) => tab.getAttribute(H.TAB.attr) || '';
  const withValue = (hook, value, within = document) =>
    [...within.querySelectorAll(hook.sel)].find(el => el.getAttribute(hook.attr) === value);
  const mark = () => {
    flag(root, 'data-app-bldc', [...document.querySelectorAll(H.SELECTED_TAB.sel)]
      .some(tab => tabTitle(tab).startsWith('BLDC')));
    const fit = new Map(), columns = new Map(), windows = new Map(), hidden = new Map();
    for (const side of ['left', 'right']) {
      const region = withValue(H.DOCK_REGION, side);
      flag(root, `data-app-rail-${side}`, !!(region && region.querySelector(H.DOCK_COLUMN_RAIL.sel)));
      const shadow = region && region.previousElementSibling;  // the region's shadow
      if (shadow && shadow.tagName === 'DIV' && shadow.parentElement.hasAttribute(H.DOCK_ROOT.attr)) fit.set(shadow, side);
    }
    for (const col of document.querySelectorAll(H.DOCK_COLUMN.sel)) {
      const up = col.parentElement;  // a div inside a docked region, not the region itself
      if (up && up.tagName === 'DIV' && up.parentElement && up.parentElement.closest(H.DOCK_REGION.sel)) {
        columns.set(up, '');
      }
    }
    for (const w of document.querySelectorAll(H.FLOATING_WINDOW.sel)) {
      if (withValue(H.TAB, 'Overview', w)) windows.set(w, '');
    }
    for (const uuid of hiddenFields) {
      const label = withValue(H.FIELD_LABEL, uuid);
      const row = label && label.closest(H.FIELD_ROW.sel);
      if (row && row.parentElement && row.parentElement.tagName === 'DIV') hidden.set(row.parentElement, '');
    }
    only('data-app-fit', fit); only('data-app-column', columns);
    only('data-app-overview-window', windows); only('data-app-hidden', hidden);
    closeWebGlNotices();
  };
  // viser's notice of a software WebGL stays until closed, over the results' tab row and key numbers.
  // It concerns the 3D view's speed only (the plots are SVG): closed while no 3D view is shown. (Its
  // "WebGL unavailable" notice stays: then the 3D view cannot work at all.)
  const closeWebGlNotices = () => {
    for (const title of document.querySelectorAll(H.NOTIFICATION_TITLE.sel)) {
      if (title.textContent.trim() !== H.SOFTWARE_WEBGL_NOTICE.text) continue;
      const shown3d = [...document.querySelectorAll('canvas')]
        .some(c => c.clientWidth > SCENE_MIN_PX && getComputedStyle(c).visibility !== 'hidden');
      const close = title.closest(H.NOTIFICATION.sel);
      const button = close && close.querySelector(H.NOTIFICATION_CLOSE.sel);
      if (!shown3d && button) button.click();
    }
  };
  // A slider's mark labels that would overlap (with ideal sensors K_recommended is K_limit/2: 0.3 decade
  // on a 5.7-decade track) are moved apart (CSS `translate`, which leaves Mantine's own transform alone): a pair
  // shares what it overlaps, except that the track's end labels (its first two marks) stay put.
  // A few passes settle a crowd. Looked at in the next animation frame after a change outside the
  // plots (the layout is then computed anyway); moved only when a slider's marks, widths or fonts
  // changed.
  const spread = () => {
    for (const slider of document.querySelectorAll(H.SLIDER.sel)) {
      const width = slider.clientWidth;
      if (width === 0) continue;  // hidden: measured when shown
      const labels = [...slider.querySelectorAll(H.SLIDER_MARK_LABEL.sel)];
      const key = width + '|' + labels.map(l => l.textContent + l.offsetWidth
        + (l.parentElement.getAttribute('style') || '')).join('|');
      if (slider.__appMarksKey === key) continue;
      slider.__appMarksKey = key;
      for (const l of labels) l.style.translate = '';
      const boxes = labels.map((l, i) => ({l, r: l.getBoundingClientRect(), dx: 0, fixed: i < 2}))
        .sort((a, b) => a.r.x - b.r.x);
      for (let pass = 0; pass < 8; pass++) {
        let moved = false;
        for (let i = 1; i < boxes.length; i++) {
          const a = boxes[i - 1], b = boxes[i], overlap = a.r.right + a.dx + 4 - (b.r.left + b.dx);
          if (overlap <= 0.5) continue;
          const share = a.fixed ? 0 : b.fixed ? 1 : 0.5;
          a.dx -= overlap * share; b.dx += overlap * (1 - share); moved = true;
        }
        if (!moved) break;
      }
      for (const {l, dx} of boxes) if (dx) l.style.translate = `${dx.toFixed(1)}px 0`;
    }
  };
  let queued = false;
  const spreadSoon = () => {
    if (!queued) { queued = true; requestAnimationFrame(() => { queued = false; spread(); }); }
  };
  window.__appHideField = (uuid) => { hiddenFields.push(uuid); mark(); };  // a field made later
  // mutations inside a plot (Plotly redraws) change none of the marks, nor any slider
  const outside = (r) => { const el = r.target.closest ? r.target : r.target.parentElement;
    return !(el && el.closest('.js-plotly-plot')); };
  // a mark's value or label changes in place (its wrapper's style, its text): only spread() looks
  const marksOnly = (r) => r.type === 'characterData' || r.attributeName === 'style';
  new MutationObserver((records) => {
    if (records.some(r => !marksOnly(r) && outside(r))) mark();
    if (records.some(outside)) spreadSoon();
  }).observe(document.body, {
    childList: true, subtree: true, attributes: true, characterData: true,
    attributeFilter: [H.SELECTED_TAB.attr, H.DOCK_COLUMN_RAIL.attr, H.DOCK_REGION.attr, H.FLOATING_WINDOW.attr,
                      H.TAB.attr, 'style'] });
  new MutationObserver(spreadSoon).observe(document.head, {childList: true});  // a style sheet added
  window.addEventListener('resize', spreadSoon);
  document.fonts.ready.then(spreadSoon);
  mark(); spreadSoon();
})();
