// Checks that a reader can read values off every inline SVG plot of the page and zoom into
// it (issue 29), as tests/cli/plot_layout.sh --interaction injects it after the layout check.
// It knows nothing of how the page does it but two names: the readout is the element
// id jg-plot-readout, showing "name = value" lines. Everything else is read the way a reader
// reads it, off the axes' visible tick labels (numbers just below / left of the frame):
//  - hover: a mousemove over the frame shows the readout, its first two values the x and y
//    the axes give at the pointer (within 1 % of the axis span);
//  - zoom: a drag across 30 %..60 % of the frame's width leaves x tick labels that say the
//    x range shown is what was under 30 %..60 % before, all on one straight scale (no stale
//    label left), every line reaching into the frame and out of it is clipped to the frame,
//    and the hover reads the new scale;
//  - wheel: Shift + wheel up over the frame narrows the x range about the pointer (the x
//    under it stays), within the range shown before;
//  - reset: a double-click brings back the first range and every line as it was drawn.
// Writes "PLOT-INTERACTION: ok ..." or "PLOT-INTERACTION: FAIL" and one line per fault into a
// PRE element, id plot-interaction-verdict.
(function () {
  'use strict';
  const faults = [];
  const NUM = /^[-\u2212]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$/;

  // The frame: the largest closed path (gnuplot's border), in the svg's user space.
  function frameOf(svg) {
    let best = null;
    for (const p of svg.querySelectorAll('path')) {
      if (!/[zZ]/.test(p.getAttribute('d') || '') || p.closest('defs, clipPath')) continue;
      const b = p.getBBox(), m = p.getCTM();
      const f = {l: b.x + m.e, t: b.y + m.f, r: b.x + b.width + m.e, b: b.y + b.height + m.f};
      if (!best || (f.r - f.l) * (f.b - f.t) > (best.r - best.l) * (best.b - best.t)) best = f;
    }
    return best;
  }
  // The visible numeric labels beside the frame's bottom (x) or left (y) edge, fitted to one
  // straight scale value = a + s * px; null without two distinct ones, or when one is off it.
  function axis(svg, F, which) {
    const pts = [];
    for (const t of svg.querySelectorAll('text')) {
      const s = t.textContent.trim().replace('\u2212', '-');
      if (!NUM.test(s) || t.getBoundingClientRect().width === 0) continue;
      const b = t.getBBox(), m = t.getCTM(), cx = b.x + b.width / 2 + m.e, cy = b.y + b.height / 2 + m.f;
      if (which === 'x' && cy > F.b && cy < F.b + 30 && cx > F.l - 5 && cx < F.r + 5) pts.push([cx, parseFloat(s)]);
      if (which === 'y' && b.x + b.width + m.e < F.l && cy > F.t - 5 && cy < F.b + 5) pts.push([cy, parseFloat(s)]);
    }
    if (pts.length < 2) return null;
    pts.sort((p, q) => p[0] - q[0]);
    const [p0, p1] = [pts[0], pts[pts.length - 1]];
    if (p1[0] - p0[0] < 1) return null;
    const s = (p1[1] - p0[1]) / (p1[0] - p0[0]), at = (px) => p0[1] + s * (px - p0[0]);
    const span = Math.abs(p1[1] - p0[1]);
    const off = pts.find(([px, v]) => Math.abs(at(px) - v) > 0.005 * span);
    return off ? {bad: `label ${off[1]} is off the scale of ${p0[1]}..${p1[1]}`} : {at};
  }
  function fire(svg, type, px, py) {
    const c = new DOMPoint(px, py).matrixTransform(svg.getScreenCTM());
    svg.dispatchEvent(new MouseEvent(type, {clientX: c.x, clientY: c.y, bubbles: true, cancelable: true, button: 0, buttons: type === 'mouseup' ? 0 : 1}));
  }
  // The readout's values ("name = value" lines) after a hover at (px, py), or null.
  function hover(svg, px, py) {
    fire(svg, 'mousemove', px, py);
    const r = document.getElementById('jg-plot-readout');
    if (!r || r.getClientRects().length === 0) return null;
    return Array.from(r.textContent.matchAll(/=\s*([-\u2212]?[\d.]+(?:[eE][-+]?\d+)?)/g)).map((m) => parseFloat(m[1].replace('\u2212', '-')));
  }
  // Lines that reach into the frame and out of it (the zoomed traces), each of which must be
  // clipped (clip-path on it or a parent) to a region inside the frame; their count.
  function unclipped(svg, F) {
    let n = 0;
    for (const p of svg.querySelectorAll('path')) {
      if (p.closest('defs, clipPath')) continue;
      const b = p.getBBox(), m = p.getCTM(), l = b.x + m.e, t = b.y + m.f, r = l + b.width, bt = t + b.height;
      const meets = l < F.r && r > F.l && t < F.b && bt > F.t, inside = l >= F.l - 1.5 && r <= F.r + 1.5 && t >= F.t - 1.5 && bt <= F.b + 1.5;
      if (!meets || inside) continue;
      const holder = p.closest('[clip-path]'), id = holder && (holder.getAttribute('clip-path').match(/#([^)"']+)/) || [])[1];
      const shape = id && svg.querySelector(`clipPath[id="${id}"] > *`), c = shape && shape.getBBox();  // its shape
      if (!c || c.x < F.l - 1.5 || c.x + c.width > F.r + 1.5 || c.y < F.t - 1.5 || c.y + c.height > F.b + 1.5) ++n;
    }
    return n;
  }
  const near = (a, b, span, tol) => Math.abs(a - b) <= tol * Math.abs(span);
  const lines = (svg) => Array.from(svg.querySelectorAll('path')).map((p) => p.getAttribute('d')).join('|');

  function checkHover(svg, name, F, X, Y, when) {
    const px = F.l + 0.37 * (F.r - F.l), py = F.t + 0.41 * (F.b - F.t);
    const v = hover(svg, px, py);
    if (!v || v.length < 2) { faults.push(`${name}: ${when}: no readout with x and y appears on hovering the frame`); return; }
    const xs = X.at(F.r) - X.at(F.l), ys = Y.at(F.t) - Y.at(F.b);
    if (!near(v[0], X.at(px), xs, 0.01)) faults.push(`${name}: ${when}: the readout's x ${v[0]} is not the axis' ${X.at(px).toPrecision(5)}`);
    if (!near(v[1], Y.at(py), ys, 0.01)) faults.push(`${name}: ${when}: the readout's y ${v[1]} is not the axis' ${Y.at(py).toPrecision(5)}`);
  }
  function checkWheel(svg, name, F, X0) {
    const px = F.l + 0.4 * (F.r - F.l), c = new DOMPoint(px, (F.t + F.b) / 2).matrixTransform(svg.getScreenCTM());
    svg.dispatchEvent(new WheelEvent('wheel', {clientX: c.x, clientY: c.y, deltaY: -100, shiftKey: true, bubbles: true, cancelable: true}));
    const X1 = axis(svg, F, 'x'), span0 = X0.at(F.r) - X0.at(F.l);
    if (!X1 || X1.bad) { faults.push(`${name}: after Shift + wheel the x axis has no readable scale${X1 ? ': ' + X1.bad : ''}`); return; }
    const span1 = X1.at(F.r) - X1.at(F.l);
    if (!(span1 < 0.95 * span0) || X1.at(F.l) < X0.at(F.l) - 0.01 * span0 || X1.at(F.r) > X0.at(F.r) + 0.01 * span0 || !near(X1.at(px), X0.at(px), span0, 0.01)) {
      faults.push(`${name}: Shift + wheel over x ${X0.at(px).toPrecision(5)} shows ${X1.at(F.l).toPrecision(5)}..${X1.at(F.r).toPrecision(5)}, ` +
                  `not a narrower range about it within ${X0.at(F.l).toPrecision(5)}..${X0.at(F.r).toPrecision(5)}`);
    }
  }
  function checkZoom(svg, name, F, X0, Y) {
    const W = F.r - F.l, py = F.t + 0.5 * (F.b - F.t), before = lines(svg);
    fire(svg, 'mousedown', F.l + 0.3 * W, py);
    fire(svg, 'mousemove', F.l + 0.45 * W, py);
    fire(svg, 'mouseup', F.l + 0.6 * W, py);
    const X1 = axis(svg, F, 'x'), want = [X0.at(F.l + 0.3 * W), X0.at(F.l + 0.6 * W)];
    if (!X1 || X1.bad) { faults.push(`${name}: after a drag zoom the x axis has no readable scale${X1 ? ': ' + X1.bad : ''}`); return; }
    const got = [X1.at(F.l), X1.at(F.r)], span = want[1] - want[0];
    if (!near(got[0], want[0], span, 0.02) || !near(got[1], want[1], span, 0.02)) {
      faults.push(`${name}: a drag over ${want.map((v) => v.toPrecision(4)).join('..')} shows x ${got.map((v) => v.toPrecision(4)).join('..')}`);
      return;
    }
    if (lines(svg) === before) faults.push(`${name}: zoomed, but no line was redrawn`);
    const loose = unclipped(svg, F);
    if (loose) faults.push(`${name}: zoomed, ${loose} lines run out of the frame unclipped`);
    checkHover(svg, name, F, X1, Y, 'zoomed');
    checkWheel(svg, name, F, X1);
    fire(svg, 'dblclick', F.l + 0.5 * W, py);
    const X2 = axis(svg, F, 'x');
    if (!X2 || X2.bad || !near(X2.at(F.l), X0.at(F.l), X0.at(F.r) - X0.at(F.l), 0.001) || !near(X2.at(F.r), X0.at(F.r), X0.at(F.r) - X0.at(F.l), 0.001)) {
      faults.push(`${name}: a double-click does not bring back the x range ${X0.at(F.l).toPrecision(4)}..${X0.at(F.r).toPrecision(4)}`);
    }
    if (lines(svg) !== before) faults.push(`${name}: after the reset the lines are not as first drawn`);
  }

  const svgs = Array.from(document.querySelectorAll('svg')).filter((s) => !s.parentElement.closest('svg'));
  let checked = 0;
  svgs.forEach((svg, k) => {
    const title = Array.from(svg.querySelectorAll('text')).map((t) => t.textContent.trim()).find((s) => s.length > 12) || '';
    const name = `plot ${k + 1} ("${title.slice(0, 60)}")`;
    const F = frameOf(svg), X = F && axis(svg, F, 'x'), Y = F && axis(svg, F, 'y');
    if (!F || !X || X.bad || !Y || Y.bad) { faults.push(`${name}: no frame with readable x and y axes`); return; }
    ++checked;
    checkHover(svg, name, F, X, Y, 'whole range');
    checkZoom(svg, name, F, X, Y);
    svg.dispatchEvent(new MouseEvent('mouseleave'));
  });
  if (checked === 0) faults.push('no plot to check');
  const pre = document.createElement('pre');
  pre.id = 'plot-interaction-verdict';
  pre.textContent = (faults.length ? `PLOT-INTERACTION: FAIL ${faults.length} faults` : 'PLOT-INTERACTION: ok') +
    ` (${checked} of ${svgs.length} plots hovered, zoomed and reset)\n` + faults.map((f) => 'PLOT-INTERACTION-FAULT: ' + f).join('\n');
  document.body.appendChild(pre);
})();
