// Installed once per page by app/ui/layout.py (page_marks_js): marks the elements the page's CSS
// styles, instead of CSS :has() rules (with one in the page every forced layout re-styled it all).
(() => { if (window.__appPageMarks) return; window.__appPageMarks = true;
  const hiddenFields = HIDDEN_FIELDS;  // text fields the page's scripts write into
  const root = document.documentElement;
  const flag = (el, name, on) => { if (el.hasAttribute(name) !== on) el.toggleAttribute(name, on); };
  const only = (name, want) => {  // the attribute `name` on exactly the elements of `want` (value: want's map)
    for (const el of document.querySelectorAll(`[${name}]`)) if (!want.has(el)) el.removeAttribute(name);
    for (const [el, v] of want) if (el.getAttribute(name) !== v) el.setAttribute(name, v); };
  const mark = () => {
    flag(root, 'data-app-bldc', !!document.querySelector('[role="tab"][aria-selected="true"][title^="BLDC"]'));
    const fit = new Map(), columns = new Map(), windows = new Map(), hidden = new Map();
    for (const side of ['left', 'right']) {
      const region = document.querySelector(`[data-dock-region="${side}"]`);
      flag(root, `data-app-rail-${side}`, !!(region && region.querySelector('[data-dock-column-rail]')));
      const shadow = region && region.previousElementSibling;
      if (shadow && shadow.tagName === 'DIV' && shadow.parentElement.hasAttribute('data-dock-root')) fit.set(shadow, side);
    }
    for (const col of document.querySelectorAll('[data-dock-region] [data-dock-column]')) {
      const up = col.parentElement;  // a div inside a docked region, not the region itself
      if (up && up.tagName === 'DIV' && up.parentElement && up.parentElement.closest('[data-dock-region]')) {
        columns.set(up, '');
      }
    }
    for (const w of document.querySelectorAll('[data-floating-window]')) {
      if (w.querySelector('[role="tab"][title="Overview"]')) windows.set(w, '');
    }
    for (const uuid of hiddenFields) {
      const label = document.querySelector(`label[for="${uuid}"]`);
      const row = label && label.closest('.mantine-Flex-root');
      if (row && row.parentElement && row.parentElement.tagName === 'DIV') hidden.set(row.parentElement, '');
    }
    only('data-app-fit', fit); only('data-app-column', columns);
    only('data-app-overview-window', windows); only('data-app-hidden', hidden);
  };
  window.__appHideField = (uuid) => { hiddenFields.push(uuid); mark(); };  // a field made later
  // mutations inside a plot (Plotly redraws) change none of the marks
  const outside = (r) => !(r.target.closest && r.target.closest('.js-plotly-plot'));
  new MutationObserver((records) => { if (records.some(outside)) mark(); }).observe(document.body, {
    childList: true, subtree: true, attributes: true,
    attributeFilter: ['aria-selected', 'data-dock-column-rail', 'data-dock-region', 'data-floating-window', 'title'] });
  mark();
})();
