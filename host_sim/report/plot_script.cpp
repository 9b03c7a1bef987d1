// The page script of the report plots (svg_plot.hpp, plot_script): hover readout and x zoom.
// Kept as one raw string so that a report stays one file with no build step for the script;
// tests/cli/plot_interaction_check.js checks it in headless Chromium on the demo's report.
#include "report/svg_plot.hpp"

namespace jg::report {
namespace {
constexpr const char* kPlotScript = R"JS(
// Hover readout and x zoom for the page's gnuplot plots (issue 29), offline: no library.
// Each svg element of class "plot" carries, from svg_plot.cpp, data-frame (the frame's left
// top right bottom in px), data-range (x and y range drawn) and data-x-label / data-y-label. The
// traces stay gnuplot's paths: a zoom rewrites the x of their points inside the frame and
// clips them to the frame; y is not zoomed, so gnuplot's y axis stays right. While zoomed,
// gnuplot's x ticks (which would lie) are hidden and ticks for the shown range drawn instead.
// Hover: the pointer's x and y in the axes' units and the value of the trace nearest to it,
// in one floating element (id jg-plot-readout). Drag across the frame: zoom to that x
// range; Shift + wheel: zoom in or out about the pointer (the plain wheel stays the page's
// scrolling); double-click: back to the whole range. The svg's data-view holds the x range shown.
(function () {
  'use strict';
  const NS = 'http://www.w3.org/2000/svg';
  let readout = null;  // one for the page: only one plot is under the pointer

  const nums = (s) => (s || '').trim().split(/\s+/).map(Number);
  // Decimals that show a value to about a thousandth of the span it is read against.
  const fmt = (v, span) => v.toFixed(Math.max(0, Math.min(9, 3 - Math.floor(Math.log10(Math.abs(span) || 1)))));

  // The sub-paths of a d written with absolute M and L only, as gnuplot writes lines; null
  // for anything else (curves, closed shapes such as the frame), which is then left alone.
  function parse(d) {
    const t = d.match(/[A-Za-z]|-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?/g) || [];
    const out = [];
    let cmd = '';
    for (let i = 0; i < t.length;) {
      if (/[A-Za-z]/.test(t[i])) cmd = t[i++];
      if ((cmd !== 'M' && cmd !== 'L') || (cmd === 'L' && !out.length) || i + 1 >= t.length) return null;
      if (cmd === 'M') { out.push([]); cmd = 'L'; }
      out[out.length - 1].push([parseFloat(t[i]), parseFloat(t[i + 1])]);
      i += 2;
    }
    return out;
  }
  const write = (subs) => subs.map((s) => s.map((p, i) => (i ? 'L' : 'M') + p[0].toFixed(2) + ',' + p[1].toFixed(2)).join(' ')).join(' ');
  const within = (s, F) => s.every(([x, y]) => x >= F.l - 1 && x <= F.r + 1 && y >= F.t - 1 && y <= F.b + 1);
  const vertical = (subs) => subs.every((s) => s.every((p) => Math.abs(p[0] - s[0][0]) < 0.01));

  // Pixel <-> data: x through the range shown (P.view), y through the range drawn.
  const xData = (P, px) => P.view[0] + (px - P.F.l) / (P.F.r - P.F.l) * (P.view[1] - P.view[0]);
  const xPx = (P, x) => P.F.l + (x - P.view[0]) / (P.view[1] - P.view[0]) * (P.F.r - P.F.l);
  const yData = (P, py) => P.R[2] + (P.F.b - py) / (P.F.b - P.F.t) * (P.R[3] - P.R[2]);

  function el(tag, attrs, parent) {
    const e = document.createElementNS(NS, tag);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }

  // Sorts the plot's paths: gnuplot's x ticks and vertical grid lines (hidden while zoomed),
  // and lines inside the frame (traces, thresholds, markers: zoomed). A path with pieces
  // inside and outside the frame (a trace and its legend sample) is split in two first.
  function collect(P, clipId) {
    for (const path of Array.from(P.svg.querySelectorAll('path'))) {
      if (path.closest('defs, clipPath')) continue;
      const subs = parse(path.getAttribute('d') || '');
      if (!subs || !subs.length) continue;
      const tick = path.parentNode.querySelector('text') !== null;  // gnuplot groups a tick with its label
      if (path.classList.contains('gridline') || tick) {
        if (vertical(subs)) P.xticks.push(tick ? path.parentNode : path);
        continue;
      }
      const inside = subs.filter((s) => within(s, P.F)), outside = subs.filter((s) => !within(s, P.F));
      if (!inside.length) continue;
      if (outside.length) path.parentNode.insertBefore(path.cloneNode(false), path).setAttribute('d', write(outside));
      path.setAttribute('d', write(inside));
      path.setAttribute('clip-path', `url(#${clipId})`);
      const group = path.closest('[data-series]'), key = group && group.querySelector('text');
      P.traces.push({path, d0: path.getAttribute('d'), label: group ? (key ? key.textContent.trim() : 'trace ' + group.dataset.series) : null,
                     pts: inside.map((s) => s.map(([x, y]) => [xData(P, x), y]))});
    }
  }

  // The x ticks for the range shown: steps of 1, 2 or 5 times a power of ten, about six.
  function drawTicks(P) {
    while (P.ticks.firstChild) P.ticks.removeChild(P.ticks.firstChild);
    if (!P.zoomed) return;
    const span = P.view[1] - P.view[0], raw = span / 6, mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw);
    const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
    const first = Math.ceil(P.view[0] / step);
    for (let i = first; i * step <= P.view[1] + step * 1e-6; ++i) {  // by index: no summed rounding
      const x = i * step, px = xPx(P, x);
      el('path', {d: `M${px.toFixed(2)},${P.F.b} L${px.toFixed(2)},${P.F.t}`, stroke: '#dddddd', 'stroke-dasharray': '2,4'}, P.ticks);
      el('text', {x: px.toFixed(2), y: P.labelY}, P.ticks).textContent = x.toFixed(decimals);
    }
  }

  // Shows the x range [lo, hi] (the whole range when lo is null); no deeper than a millionth
  // of the whole range, where the ticks' steps would drown in rounding.
  function zoom(P, lo, hi) {
    if (lo !== null && !(hi - lo > 1e-6 * (P.R[1] - P.R[0]))) return;
    P.view = lo === null ? [P.R[0], P.R[1]] : [lo, hi];
    P.zoomed = lo !== null;
    for (const t of P.traces) {
      t.path.setAttribute('d', P.zoomed ? write(t.pts.map((s) => s.map(([x, y]) => [xPx(P, x), y]))) : t.d0);
    }
    for (const e of P.xticks) e.style.display = P.zoomed ? 'none' : '';
    drawTicks(P);
    P.svg.dataset.view = P.view.join(' ');
  }

  // The value at x of the trace nearest to y (data units), or null: traces are read off
  // their drawn points, linearly between two (to the 0.01 px gnuplot writes).
  function nearest(P, x, y) {
    let best = null;
    for (const t of P.traces) {
      if (t.label === null) continue;
      for (const s of t.pts) {
        for (let i = 1; i < s.length; ++i) {
          const [a, b] = s[i - 1][0] <= s[i][0] ? [s[i - 1], s[i]] : [s[i], s[i - 1]];
          if (x < a[0] || x > b[0] || b[0] === a[0]) continue;
          const py = a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0]), v = yData(P, py);
          if (!best || Math.abs(v - y) < Math.abs(best.v - y)) best = {v, py, label: t.label};
        }
      }
    }
    return best;
  }

  function showReadout(P, e, px, py) {
    if (!readout) {
      readout = document.createElement('div');
      readout.id = 'jg-plot-readout';
      readout.style.cssText = 'position:fixed;pointer-events:none;background:#fff;border:1px solid #888;padding:2px 6px;' +
        'font:12px monospace;white-space:pre;z-index:10;display:none';
      document.body.appendChild(readout);
    }
    const x = xData(P, px), y = yData(P, py), xs = P.view[1] - P.view[0], ys = P.R[3] - P.R[2];
    const n = nearest(P, x, y);
    const lines = [`${P.svg.dataset.xLabel || 'x'} = ${fmt(x, xs)}`, `${P.svg.dataset.yLabel || 'y'} = ${fmt(y, ys)}`];
    if (n) lines.push(`${n.label} = ${fmt(n.v, ys)}`);
    lines.push(P.zoomed ? 'drag or Shift+wheel: zoom, double-click: whole range' : 'drag across or Shift+wheel: zoom in x');
    readout.textContent = lines.join('\n');
    readout.style.display = 'block';
    // Beside the pointer, on its left near the window's right edge so that it stays in view.
    const w = readout.offsetWidth;
    readout.style.left = (e.clientX + 14 + w > window.innerWidth ? e.clientX - 14 - w : e.clientX + 14) + 'px';
    readout.style.top = (e.clientY + 14) + 'px';
    P.cross.setAttribute('x1', px); P.cross.setAttribute('x2', px);
    P.cross.style.visibility = 'visible';
    P.dot.style.visibility = n ? 'visible' : 'hidden';
    if (n) { P.dot.setAttribute('cx', px); P.dot.setAttribute('cy', n.py); }
  }
  function hide(P) {
    if (readout) readout.style.display = 'none';
    P.cross.style.visibility = P.dot.style.visibility = 'hidden';
    P.band.style.visibility = 'hidden';
    P.drag = null;
  }

  // Pointer events in the svg's own units (whatever CSS scales it to).
  function listen(P) {
    const at = (e) => new DOMPoint(e.clientX, e.clientY).matrixTransform(P.svg.getScreenCTM().inverse());
    const inFrame = (p) => p.x >= P.F.l && p.x <= P.F.r && p.y >= P.F.t && p.y <= P.F.b;
    P.svg.addEventListener('mousemove', (e) => {
      const p = at(e);
      if (!inFrame(p)) { hide(P); return; }
      showReadout(P, e, p.x, p.y);
      if (P.drag !== null) {
        P.band.setAttribute('x', Math.min(P.drag, p.x)); P.band.setAttribute('width', Math.abs(p.x - P.drag));
        P.band.style.visibility = 'visible';
      }
    });
    P.svg.addEventListener('mousedown', (e) => {
      const p = at(e);
      if (e.button !== 0 || !inFrame(p)) return;
      P.drag = p.x;
      e.preventDefault();  // no text selection while dragging
    });
    P.svg.addEventListener('mouseup', (e) => {
      const x0 = P.drag, x1 = Math.min(P.F.r, Math.max(P.F.l, at(e).x));
      P.drag = null;
      P.band.style.visibility = 'hidden';
      if (x0 !== null && Math.abs(x1 - x0) >= 4) zoom(P, xData(P, Math.min(x0, x1)), xData(P, Math.max(x0, x1)));  // 4 px: not a click
    });
    P.svg.addEventListener('wheel', (e) => {
      const p = at(e), d = e.deltaY || e.deltaX;  // some systems turn Shift + wheel sideways
      if (!e.shiftKey || !d || !inFrame(p)) return;
      e.preventDefault();
      const x = xData(P, p.x), k = d > 0 ? 1.25 : 0.8, lo = x - (x - P.view[0]) * k, hi = x + (P.view[1] - x) * k;
      if (lo <= P.R[0] && hi >= P.R[1]) zoom(P, null);  // out to the whole range: no further
      else zoom(P, Math.max(lo, P.R[0]), Math.min(hi, P.R[1]));
    }, {passive: false});
    P.svg.addEventListener('mouseleave', () => hide(P));
    P.svg.addEventListener('dblclick', (e) => { e.preventDefault(); zoom(P, null); });
  }

  function setup(svg, k) {
    const f = nums(svg.dataset.frame), R = nums(svg.dataset.range);
    if (f.length !== 4 || R.length !== 4 || f.concat(R).some((v) => !isFinite(v)) || !(R[1] > R[0]) || !(R[3] > R[2])) return;
    const P = {svg, F: {l: f[0], t: f[1], r: f[2], b: f[3]}, R, view: [R[0], R[1]], zoomed: false, traces: [], xticks: [], drag: null};
    const clipId = 'jg-plot-clip-' + k;  // unique on the page: one per plot
    el('rect', {x: P.F.l, y: P.F.t, width: P.F.r - P.F.l, height: P.F.b - P.F.t}, el('clipPath', {id: clipId}, el('defs', {}, svg)));
    collect(P, clipId);
    // gnuplot's x tick labels stand at one height below the frame; ours take the same.
    const label = P.xticks.map((g) => g.querySelector && g.querySelector('text')).find((t) => t);
    P.labelY = label ? label.getCTM().f : P.F.b + 20;  // the baseline: its group's translate
    P.ticks = el('g', {fill: 'rgb(68,68,68)', 'font-family': 'sans', 'font-size': '11', 'text-anchor': 'middle'}, svg);
    // Hover marks and the drag band, inside the frame (the layout check sees them there).
    P.cross = el('line', {x1: P.F.l, x2: P.F.l, y1: P.F.t, y2: P.F.b, stroke: '#888', 'stroke-width': 0.6, style: 'visibility:hidden'}, svg);
    P.dot = el('circle', {r: 3, cx: P.F.l, cy: P.F.t, fill: 'none', stroke: '#222', style: 'visibility:hidden'}, svg);
    P.band = el('rect', {x: P.F.l, y: P.F.t, width: 0, height: P.F.b - P.F.t, fill: 'rgba(31,119,180,0.15)', style: 'visibility:hidden'}, svg);
    svg.style.cursor = 'crosshair';
    svg.dataset.view = P.view.join(' ');
    listen(P);
  }

  document.querySelectorAll('svg.plot').forEach(setup);
})();
)JS";
}  // namespace

std::string plot_script() { return std::string("<script>") + kPlotScript + "</script>\n"; }

}  // namespace jg::report
