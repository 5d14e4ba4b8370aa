// Canvas drawing for the studio: min/max bands over time, bar charts and
// point trails. Written for evflow; no library.
"use strict";
const plot = (() => {
  function fit(canvas) {
    const r = window.devicePixelRatio || 1;
    const w = Math.max(50, Math.floor(canvas.clientWidth * r)), h = Math.max(30, Math.floor(canvas.clientHeight * r));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    const g = canvas.getContext("2d");
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.clearRect(0, 0, w, h);
    return { g, w, h, r };
  }
  function fmt(v) {
    const a = Math.abs(v);
    if (a === 0) return "0";
    if (a >= 1e6 || a < 1e-2) return v.toExponential(1);
    return String(Number(v.toPrecision(a >= 1000 ? 6 : 3)));
  }
  function range(lo, hi) {
    if (!(hi > lo)) { const c = isFinite(lo) ? lo : 0; return [c - 1, c + 1]; }
    const pad = (hi - lo) * 0.08;
    return [lo - pad, hi + pad];
  }
  // A band between lo[i] and hi[i] at times t[i] (seconds) over [t0, t1].
  function band(canvas, s, t0, t1, color) {
    const { g, w, h, r } = fit(canvas);
    let ylo = Infinity, yhi = -Infinity;
    for (let i = 0; i < s.t.length; i++) {
      if (s.t[i] < t0 || s.lo[i] === null) continue;
      ylo = Math.min(ylo, s.lo[i]); yhi = Math.max(yhi, s.hi[i]);
    }
    [ylo, yhi] = range(ylo, yhi);
    const X = t => (t - t0) / (t1 - t0) * w, Y = v => h - (v - ylo) / (yhi - ylo) * h;
    g.strokeStyle = "#dde"; g.lineWidth = r;
    if (ylo < 0 && yhi > 0) { g.beginPath(); g.moveTo(0, Y(0)); g.lineTo(w, Y(0)); g.stroke(); }
    g.fillStyle = color; g.strokeStyle = color;
    g.beginPath();
    let open = false;
    for (let i = 0; i < s.t.length; i++) {
      if (s.t[i] < t0) continue;
      if (s.lo[i] === null) { open = false; continue; }
      const x = X(s.t[i]), a = Y(s.hi[i]), b = Y(s.lo[i]);
      g.fillRect(x, a, Math.max(r, 1), Math.max(b - a, r));
      if (!open) { g.moveTo(x, (a + b) / 2); open = true; } else g.lineTo(x, (a + b) / 2);
    }
    g.stroke();
    g.fillStyle = "#556"; g.font = `${10 * r}px sans-serif`;
    g.fillText(fmt(yhi), 2, 10 * r); g.fillText(fmt(ylo), 2, h - 2);
  }
  // Several min/max series on one shared scale, each as the line through
  // its bands' middles, with a legend: [{ s, color, name }].
  function overlay(canvas, list, t0, t1) {
    const { g, w, h, r } = fit(canvas);
    let ylo = Infinity, yhi = -Infinity;
    for (const { s } of list) {
      for (let i = 0; i < s.t.length; i++) {
        if (s.t[i] < t0 || s.lo[i] === null) continue;
        ylo = Math.min(ylo, s.lo[i]); yhi = Math.max(yhi, s.hi[i]);
      }
    }
    [ylo, yhi] = range(ylo, yhi);
    const X = t => (t - t0) / (t1 - t0) * w, Y = v => h - (v - ylo) / (yhi - ylo) * h;
    g.lineWidth = r;
    list.forEach(({ s, color, name }, k) => {
      g.strokeStyle = color;
      g.beginPath();
      let open = false;
      for (let i = 0; i < s.t.length; i++) {
        if (s.t[i] < t0) continue;
        if (s.lo[i] === null) { open = false; continue; }
        const y = Y((s.lo[i] + s.hi[i]) / 2);
        if (!open) { g.moveTo(X(s.t[i]), y); open = true; } else g.lineTo(X(s.t[i]), y);
      }
      g.stroke();
      g.fillStyle = color; g.font = `${10 * r}px sans-serif`;
      g.fillText(name, w - 160 * r, (12 + 12 * k) * r);
    });
    g.fillStyle = "#556"; g.font = `${10 * r}px sans-serif`;
    g.fillText(fmt(yhi), 2, 10 * r); g.fillText(fmt(ylo), 2, h - 2);
  }
  // Bars with labels under them; counts on a log scale.
  function bars(canvas, labels, counts, title) {
    const { g, w, h, r } = fit(canvas);
    const n = counts.length, bw = w / n, top = Math.log10(1 + Math.max(1, ...counts));
    g.font = `${9 * r}px sans-serif`;
    for (let i = 0; i < n; i++) {
      const v = Math.log10(1 + counts[i]) / top * (h - 28 * r);
      g.fillStyle = i >= n - 5 ? "#d98200" : "#3566c4";
      g.fillRect(i * bw + 1, h - 14 * r - v, bw - 2, v);
      g.fillStyle = "#556";
      g.fillText(labels[i], i * bw + 2, h - 3 * r);
      if (counts[i]) g.fillText(String(counts[i]), i * bw + 2, h - 16 * r - v);
    }
    g.fillText(title, w - g.measureText(title).width - 4, 10 * r);
  }
  // Points (x, y, c) with c in [0, 1] as colour; the last one large.
  function trail(canvas, pts, xr, yr, xl, yl, background) {
    const { g, w, h, r } = fit(canvas);
    const X = x => (x - xr[0]) / (xr[1] - xr[0]) * (w - 20 * r) + 10 * r;
    const Y = y => h - 14 * r - (y - yr[0]) / (yr[1] - yr[0]) * (h - 24 * r);
    if (background) background(g, X, Y, r);
    for (let i = 0; i < pts.length; i++) {
      const [x, y, c] = pts[i], a = 0.15 + 0.85 * i / pts.length, last = i === pts.length - 1;
      g.fillStyle = `hsla(${240 - 240 * Math.min(1, Math.max(0, c))}, 85%, 45%, ${last ? 1 : a})`;
      g.beginPath(); g.arc(X(x), Y(y), (last ? 7 : 2) * r, 0, 2 * Math.PI); g.fill();
    }
    g.fillStyle = "#556"; g.font = `${10 * r}px sans-serif`;
    g.fillText(`${xl}: ${fmt(xr[0])} … ${fmt(xr[1])}`, 4, h - 2);
    g.fillText(`${yl}: ${fmt(yr[0])} … ${fmt(yr[1])}`, 4, 10 * r);
  }
  return { band, overlay, bars, trail, fmt, range };
})();
