// Checks every inline SVG plot of the page it is injected into (tests/cli/plot_layout.sh) the
// way a reader sees it, from the browser's own layout: no text over another text, no text cut
// off by the plot's edge or crossing its frame, no line leaving its frame (a line is either
// inside the frame, as traces, thresholds and markers are, or wholly outside it, as a legend's
// sample). Writes "PLOT-LAYOUT: ok ..." or "PLOT-LAYOUT: FAIL" and one line per fault into
// a PRE element, id plot-layout-verdict. Geometry is taken in each SVG's own user space (getBBox and
// getCTM), so page scrolling and CSS scaling do not matter.
(function () {
  'use strict';
  const TOL = 1.5;  // px: strokes on the frame's edge and anti-aliasing
  const faults = [];
  let nLines = 0, nTexts = 0;

  function apply(m, x, y) { return {x: m.a * x + m.c * y + m.e, y: m.b * x + m.d * y + m.f}; }
  function boxOf(points) {
    const b = {l: Infinity, t: Infinity, r: -Infinity, b: -Infinity};
    for (const p of points) {
      b.l = Math.min(b.l, p.x); b.r = Math.max(b.r, p.x);
      b.t = Math.min(b.t, p.y); b.b = Math.max(b.b, p.y);
    }
    return b;
  }
  // An element's local box mapped into its SVG's user space.
  function userBox(el) {
    const bb = el.getBBox(), m = el.getCTM();
    return boxOf([[bb.x, bb.y], [bb.x + bb.width, bb.y], [bb.x, bb.y + bb.height], [bb.x + bb.width, bb.y + bb.height]]
      .map(([x, y]) => apply(m, x, y)));
  }
  // Sub-paths of a <path> (M/L/H/V/Z, absolute or relative), <polyline> or <line>, in local
  // coordinates; null when the path uses curves (then its box stands for it).
  function subpaths(el) {
    const tag = el.tagName.toLowerCase();
    if (tag === 'line') {
      const a = (n) => parseFloat(el.getAttribute(n) || '0');
      return [[{x: a('x1'), y: a('y1')}, {x: a('x2'), y: a('y2')}]];
    }
    if (tag === 'polyline' || tag === 'polygon') {
      const v = (el.getAttribute('points') || '').trim().split(/[\s,]+/).filter((s) => s).map(Number);
      const pts = [];
      for (let i = 0; i + 1 < v.length; i += 2) pts.push({x: v[i], y: v[i + 1]});
      return [pts];
    }
    const tokens = (el.getAttribute('d') || '').match(/[A-Za-z]|-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?/g) || [];
    const out = [];
    let cur = null, cmd = '', x = 0, y = 0, i = 0;
    const next = () => parseFloat(tokens[i++]);
    while (i < tokens.length) {
      if (/[A-Za-z]/.test(tokens[i])) cmd = tokens[i++];
      const rel = cmd === cmd.toLowerCase(), c = cmd.toUpperCase();
      if (c === 'Z') { if (cur && cur.length) cur.push({...cur[0]}); continue; }
      if (c === 'M' || c === 'L') {
        const nx = next(), ny = next();
        x = rel ? x + nx : nx; y = rel ? y + ny : ny;
        if (c === 'M') { cur = []; out.push(cur); cmd = rel ? 'l' : 'L'; }
      } else if (c === 'H') { const v = next(); x = rel ? x + v : v; }
      else if (c === 'V') { const v = next(); y = rel ? y + v : v; }
      else return null;
      if (!cur) { cur = []; out.push(cur); }
      cur.push({x, y});
    }
    return out;
  }
  function userSubpaths(el) {
    const m = el.getCTM(), sp = subpaths(el);
    if (sp === null) { const b = userBox(el); return [[{x: b.l, y: b.t}, {x: b.r, y: b.b}]]; }
    return sp.map((pts) => pts.map((p) => apply(m, p.x, p.y)));
  }
  function isRectangle(all) {
    // corners, each once (a closed path repeats its start, Z may repeat it again)
    const pts = all.filter((p, i) => i === 0 || p.x !== all[i - 1].x || p.y !== all[i - 1].y);
    if (pts.length !== 5 && pts.length !== 4) return false;
    const b = boxOf(pts), eps = 0.01;
    return pts.every((p) => (Math.abs(p.x - b.l) < eps || Math.abs(p.x - b.r) < eps) && (Math.abs(p.y - b.t) < eps || Math.abs(p.y - b.b) < eps));
  }
  // The plot frame: the largest unfilled rectangle, drawn as a <rect> or as a closed path.
  function frameOf(svg) {
    let best = null, bestArea = 0;
    for (const el of svg.querySelectorAll('rect, path')) {
      if (el.closest('defs, clipPath, marker, pattern')) continue;
      let boxes = [];
      if (el.tagName.toLowerCase() === 'rect') {
        if ((el.getAttribute('fill') || '').toLowerCase() === 'none') boxes.push(userBox(el));
      } else {
        boxes = userSubpaths(el).filter(isRectangle).map(boxOf);
      }
      for (const b of boxes) {
        const area = (b.r - b.l) * (b.b - b.t);
        if (area > bestArea) { best = b; bestArea = area; }
      }
    }
    return best;
  }
  const inside = (b, f, t) => b.l >= f.l - t && b.r <= f.r + t && b.t >= f.t - t && b.b <= f.b + t;
  const meets = (b, f, t) => b.l < f.r - t && b.r > f.l + t && b.t < f.b - t && b.b > f.t + t;
  const fmt = (b) => `(${b.l.toFixed(0)},${b.t.toFixed(0)})-(${b.r.toFixed(0)},${b.b.toFixed(0)})`;

  function checkLines(svg, name, frame, view) {
    for (const el of svg.querySelectorAll('path, polyline, polygon, line')) {
      if (el.closest('defs, clipPath, marker, pattern')) continue;
      for (const pts of userSubpaths(el)) {
        if (pts.length < 2) continue;
        ++nLines;
        const b = boxOf(pts);
        if (!inside(b, frame, TOL) && meets(b, frame, TOL)) faults.push(`${name}: a line runs out of the plot frame ${fmt(frame)}: ${fmt(b)}`);
        else if (!inside(b, view, TOL)) faults.push(`${name}: a line runs out of the picture: ${fmt(b)}`);
      }
    }
  }
  function checkTexts(svg, name, frame, view) {
    const texts = [];
    for (const el of svg.querySelectorAll('text')) {
      const s = el.textContent.trim();
      if (!s) continue;
      ++nTexts;
      const b = userBox(el);
      texts.push({s, b});
      if (!inside(b, view, TOL)) faults.push(`${name}: text "${s}" is cut off by the picture's edge: ${fmt(b)}`);
      if (!inside(b, frame, TOL) && meets(b, frame, TOL)) faults.push(`${name}: text "${s}" crosses the plot frame ${fmt(frame)}: ${fmt(b)}`);
    }
    for (let i = 0; i < texts.length; ++i) {
      for (let j = i + 1; j < texts.length; ++j) {
        if (meets(texts[i].b, texts[j].b, 0.5)) faults.push(`${name}: text "${texts[i].s}" overlaps "${texts[j].s}"`);
      }
    }
  }

  const svgs = Array.from(document.querySelectorAll('svg')).filter((s) => !s.parentElement.closest('svg'));
  svgs.forEach((svg, k) => {
    const title = Array.from(svg.querySelectorAll('text')).map((t) => t.textContent.trim()).find((s) => s.length > 12) || '';
    const name = `plot ${k + 1} ("${title.slice(0, 60)}")`;
    const vb = svg.viewBox && svg.viewBox.baseVal && svg.viewBox.baseVal.width > 0 ? svg.viewBox.baseVal : null;
    const view = vb ? {l: vb.x, t: vb.y, r: vb.x + vb.width, b: vb.y + vb.height}
                    : {l: 0, t: 0, r: svg.width.baseVal.value, b: svg.height.baseVal.value};
    const frame = frameOf(svg);
    if (!frame) { faults.push(`${name}: no plot frame found`); return; }
    checkLines(svg, name, frame, view);
    checkTexts(svg, name, frame, view);
  });
  if (svgs.length === 0) faults.push('no plot on the page');
  const pre = document.createElement('pre');
  pre.id = 'plot-layout-verdict';
  pre.textContent = (faults.length ? `PLOT-LAYOUT: FAIL ${faults.length} faults` : 'PLOT-LAYOUT: ok') +
    ` (${svgs.length} plots, ${nTexts} texts, ${nLines} line pieces)\n` + faults.map((f) => 'PLOT-LAYOUT-FAULT: ' + f).join('\n');
  document.body.appendChild(pre);
})();
