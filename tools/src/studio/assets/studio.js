// The studio page: one WebSocket; a `hello` describes the session, then
// `frame`s bring decimated traces, timing, limiter states and events;
// changes go back as `set` messages and come back as `reply`s.
"use strict";
const $ = id => document.getElementById(id);
const S = {
  hello: null, taps: [], series: [], frames: 0, t: 0, tick: 0, windowS: 10, keepS: 120,
  replies: [], events: [], values: {}, limiters: {}, compute: { t: [], lo: [], hi: [] }, nextId: 1, ended: false,
  recorded: false, view: null,
};
window.studio = S;
const COLORS = ["#3566c4", "#c0162b", "#1c8a3a", "#d98200", "#7b3fb8", "#0f8a8a", "#a0522d", "#444"];
const token = new URLSearchParams(location.search).get("token");
const ws = new WebSocket(`ws://${location.host}/ws${token ? "?token=" + encodeURIComponent(token) : ""}`);
ws.onopen = () => status("connected", "ok");
ws.onclose = () => status(S.recorded ? "recorded session (loaded)" : (S.ended ? "session ended" : "disconnected"), S.recorded || S.ended ? "ended" : "bad");
ws.onmessage = m => {
  const msg = JSON.parse(m.data);
  if (msg.type === "hello") hello(msg);
  else if (msg.type === "frame") frame(msg);
  else if (msg.type === "reply") reply(msg);
  else if (msg.type === "drops") $("drops").textContent = msg.frames;
  else if (msg.type === "replay") replayShow(msg);
  else if (msg.type === "error") status(msg.message, "bad");
};
function status(text, cls) { const s = $("status"); s.textContent = text; s.className = "status " + cls; }
function el(tag, attrs, ...kids) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) if (k === "class") e.className = v; else if (k.startsWith("on")) e[k] = v; else e.setAttribute(k, v);
  for (const k of kids) e.append(k);
  return e;
}
const tapName = t => `${t.node}.${t.port}`;

function hello(h) {
  S.hello = h;
  S.recorded = h.mode === "recorded";
  $("graph-name").textContent = h.graph.name + (S.recorded ? " (recorded)" : "");
  S.taps = h.taps;
  S.series = h.taps.map(() => ({ t: [], lo: [], hi: [], last: null }));
  const picks = $("tap-picks"), traces = $("traces");
  picks.textContent = "show: "; traces.textContent = "";
  h.taps.forEach((t, i) => {
    const box = el("input", { type: "checkbox", id: "show-" + i });
    box.checked = !!t.shown;
    box.onchange = () => { $("trace-" + i).style.display = box.checked ? "" : "none"; };
    picks.append(el("label", {}, box, tapName(t) + ` (${plot.fmt(t.rate)} Hz) `));
    const row = el("div", { class: "trace", id: "trace-" + i }, el("div", { class: "label" }, tapName(t), el("br"), el("span", { id: "last-" + i, class: "small" })), el("canvas", { id: "canvas-" + i }));
    row.style.display = t.shown ? "" : "none";
    traces.append(row);
  });
  limitersInit(h.limiters);
  synthsInit(h);
  steerInit(h);
  graphDraw(h.graph);
  if (S.recorded) recordedInit(h);
}

function frame(f) {
  S.frames++;
  S.t = f.t; S.tick = f.tick;
  $("session-time").textContent = f.t.toFixed(1);
  $("session-tick").textContent = f.tick;
  for (const d of f.taps) {
    const s = S.series[d.i];
    for (let k = 0; k < d.lo.length; k++) { s.t.push(d.t0 + k * d.dt); s.lo.push(d.lo[k]); s.hi.push(d.hi[k]); }
    s.last = d.last;
    if (S.recorded) continue;
    const cut = s.t.findIndex(x => x >= s.t[s.t.length - 1] - S.keepS);
    if (cut > 0) { s.t.splice(0, cut); s.lo.splice(0, cut); s.hi.splice(0, cut); }
  }
  for (const l of f.limiters) limiterShow(l);
  for (const e of f.events) eventShow(e);
  // The value each parameter last took: a browser that joined after a
  // change (scripted, from the console or another browser) shows it too.
  for (const [k, value] of Object.entries(f.values || {})) {
    if (S.values[k] === value) continue;
    S.values[k] = value;
    const [node, param] = [k.slice(0, k.lastIndexOf(".")), k.slice(k.lastIndexOf(".") + 1)];
    steerFollow({ node, param, value });
  }
  if (f.timing) timingShow(f);
  if (f.studio) { $("drops-all").textContent = f.studio.frames_dropped; $("browsers").textContent = f.studio.browsers; }
  if (f.limiter_timelines) S.timelines = f.limiter_timelines;
  if (S.recorded && !$("steer-log").children.length) logLine($("steer-log"), "no parameter was changed during the session", "");
  if (S.recorded) draw(); else requestDraw();
}

let drawPending = false;
function requestDraw() { if (!drawPending) { drawPending = true; requestAnimationFrame(draw); } }
function draw() {
  drawPending = false;
  let t0, t1;
  if (S.view) [t0, t1] = S.view; else { t1 = Math.max(S.t, S.windowS); t0 = t1 - S.windowS; }
  S.taps.forEach((t, i) => {
    if ($("trace-" + i).style.display === "none") return;
    plot.band($("canvas-" + i), S.series[i], t0, t1, COLORS[i % COLORS.length]);
    const last = S.series[i].last;
    $("last-" + i).textContent = last === null ? "" : plot.fmt(last);
  });
  if (!S.recorded) plot.band($("compute"), S.compute, t0, t1, "#7b3fb8");
  synthsDraw(t0, t1);
  sceneDraw(t0, t1);
  if (S.recorded) markers();
}

// --- live synthesis (synth.live): its target beside the force it expects
// to render, and the rates of its running counts over the last second ---
function synthsInit(h) {
  S.synths = [];
  const box = $("synths"); box.textContent = "";
  const tap = (node, port) => findTap(t => t.node === node && t.port === port);
  for (const n of h.graph.nodes.filter(n => n.type === "synth.live")) {
    const s = { node: n.name, target: tap(n.name, "target"), predicted: tap(n.name, "predicted"),
                iterations: tap(n.name, "iterations"), fallbacks: tap(n.name, "fallbacks") };
    if (s.target < 0 && s.iterations < 0) continue;
    box.append(el("div", { class: "row" }, el("b", {}, n.name), " iterations/s: ", el("b", { id: `synth-it-${n.name}` }, "–"),
      " · fallbacks/s: ", el("b", { id: `synth-fb-${n.name}` }, "–")),
      el("canvas", { id: `synth-plot-${n.name}`, class: "synth" }));
    S.synths.push(s);
  }
  $("synth-panel").style.display = S.synths.length ? "" : "none";
}
// The rate of a running count over the last second of the span shown.
function countRate(i, t1) {
  if (i < 0) return null;
  const s = S.series[i], n = s.t.length;
  if (n < 2) return null;
  let end = n - 1;
  while (end > 0 && s.t[end] > t1) end--;
  let k = end;
  while (k > 0 && s.t[k - 1] >= s.t[end] - 1.0) k--;
  const dt = s.t[end] - s.t[k];
  return dt > 0 ? (s.hi[end] - s.hi[k]) / dt : null;
}
function synthsDraw(t0, t1) {
  for (const s of S.synths || []) {
    const it = countRate(s.iterations, t1), fb = countRate(s.fallbacks, t1);
    $(`synth-it-${s.node}`).textContent = it === null ? "–" : plot.fmt(Math.round(it));
    $(`synth-fb-${s.node}`).textContent = fb === null ? "–" : plot.fmt(Math.round(fb));
    const list = [];
    if (s.target >= 0) list.push({ s: S.series[s.target], color: "#1b7837", name: "target force (N)" });
    if (s.predicted >= 0) list.push({ s: S.series[s.predicted], color: "#c51b7d", name: "display, expected (N)" });
    // The last second of the span: long enough to compare the waveforms' shape.
    if (list.length) plot.overlay($(`synth-plot-${s.node}`), list, Math.max(t0, t1 - 1.0), t1);
  }
}

// --- limiters ---
function limitersInit(ls) {
  const box = $("limiters"); box.textContent = "";
  if (!ls.length) box.append(el("p", { class: "small" }, "this graph has no safety limiter"));
  for (const l of ls) {
    const arm = el("button", { id: `rearm-${l.node}`, onclick: () => send(`${l.node}.enable`, "true") }, "re-arm");
    const off = el("button", { id: `disable-${l.node}`, onclick: () => send(`${l.node}.enable`, "false") }, "fade out");
    if (S.recorded) { arm.disabled = true; off.disabled = true; }
    box.append(el("div", { class: "limiter" }, el("div", { class: "badge armed", id: `limiter-${l.node}` }, "ARMED"),
      el("div", {}, el("b", {}, l.node), ` |out| ≤ ${l.amplitude}`, el("br"), el("span", { class: "small", id: `limiter-info-${l.node}` })), arm, off));
  }
}
function limiterShow(l) {
  const b = $(`limiter-${l.node}`);
  if (!b) return;
  S.limiters[l.node] = l;
  b.className = "badge " + l.state;
  b.textContent = l.state.toUpperCase();
  b.title = l.source === "node" ? "as the limiter reports it (its `state` output)" : "inferred from the limiter's input, output and enable (state not recorded)";
  const counts = l.source === "node"
    ? `clamped or slew-limited ${l.clamped_samples} samples · faults ${l.faults}` + (l.watching_input ? ` · non-finite inputs ${l.non_finite_inputs}` : "")
    : `clamped ${l.clamped_samples} samples · non-finite inputs ${l.non_finite_inputs}` + (l.watching_input ? "" : " · (input not tapped: clamping not seen)");
  // A recorded session: the peaks over the whole session (the last window
  // alone is its fade-out); an input not recorded or tapped has no peak.
  const pk = l.session || l;
  const inPk = l.watching_input ? plot.fmt(pk.in_peak) : "– (input not recorded)";
  const span = l.session ? "peak over the session" : "peak";
  $(`limiter-info-${l.node}`).textContent = `enable ${l.enable} · ${span} in ${inPk} out ${plot.fmt(pk.out_peak)} · ${counts}` +
    (l.source === "node" ? " · state reported by the node" : " · state inferred (limit.state not recorded)");
}

// --- steering ---
function steerInit(h) {
  const vars = $("vars"); vars.textContent = "";
  const sel = $("param-select"); sel.textContent = "";
  $("steer-row").style.display = S.recorded ? "none" : "";
  if (S.recorded) {
    // Nothing to steer: the changes the session had, as they landed.
    $("steer-title").textContent = "Changes";
    vars.append(el("p", { class: "small", id: "steer-note" }, "a recorded session is not steered: the parameter changes it had are listed below and marked on the time axis"));
    return;
  }
  for (const v of h.vars) {
    const p = v.param || {};
    const input = el("input", { id: "var-" + v.name, size: 8, value: p.value === null || p.value === undefined ? "" : String(p.value) });
    const btn = el("button", { id: "set-" + v.name, onclick: () => send(v.name, input.value) }, "set");
    if (S.recorded) btn.disabled = true;
    vars.append(el("div", { class: "row" }, el("b", {}, v.name), input, btn, el("span", { class: "small" }, `${p.limits || ""} → ${v.uses.join(", ")}`)));
  }
  for (const p of h.params) sel.append(el("option", { value: `${p.node}.${p.param}` }, `${p.node}.${p.param}`));
  const show = () => { const p = h.params.find(q => `${q.node}.${q.param}` === sel.value); $("param-limits").textContent = p ? `${p.limits} ${p.unit || ""} — ${p.doc}` : ""; };
  sel.onchange = show; show();
  $("param-set").onclick = () => send(sel.value, $("param-value").value);
  if (S.recorded) $("param-set").disabled = true;
}
// A change that landed — from this page, another browser, the console or
// a script (`--change`) — shows in the field of every variable that sets
// that parameter (unless someone is typing in it).
function steerFollow(e) {
  for (const v of (S.hello && S.hello.vars) || []) {
    if (!v.uses.includes(`${e.node}.${e.param}`)) continue;
    const input = $("var-" + v.name);
    if (input && document.activeElement !== input) input.value = String(e.value);
  }
}
function send(target, value) {
  const id = S.nextId++;
  ws.send(JSON.stringify({ type: "set", id, target, value }));
  logLine($("steer-log"), `→ ${target} = ${value}`, "");
}
function reply(r) {
  S.replies.push(r);
  logLine($("steer-log"), (r.ok ? "✓ " : "✗ refused: ") + r.message, r.ok ? "ok" : "err");
}
function logLine(list, text, cls) {
  list.append(el("li", { class: cls }, text));
  while (list.children.length > 200) list.firstChild.remove();
  list.scrollTop = list.scrollHeight;
}

// --- timing ---
function timingShow(f) {
  const m = f.timing, o = m.overruns || {};
  const rows = [
    ["wake-up jitter µs", `p50 ${m.jitter_us.p50.toFixed(0)} · p99 ${m.jitter_us.p99.toFixed(0)} · p99.9 ${m.jitter_us.p99_9.toFixed(0)} · max ${m.jitter_us.max.toFixed(0)}`, false],
    ["compute µs", `p50 ${m.compute_us.p50.toFixed(0)} · p99.9 ${m.compute_us.p99_9.toFixed(0)} · max ${m.compute_us.max.toFixed(0)}`, false],
    ["deadline misses", `${m.misses} (longest streak ${m.longest_miss_streak})`, m.misses > 0],
    ["ring overruns", `taps ${o.taps ?? "–"} · events ${o.events ?? "–"} · timings ${o.measurements ?? "–"} · commands ${o.commands ?? "–"}`, (o.taps || 0) + (o.events || 0) > 0],
    ["host steal", m.host_steal_ms === null || m.host_steal_ms === undefined ? "n/a" : `${m.host_steal_ms.toFixed(0)} ms`, m.host_steal_ms > 0],
  ];
  const tb = $("timing"); tb.textContent = "";
  for (const [k, v, warn] of rows) tb.append(el("tr", {}, el("td", {}, k), el("td", { class: warn ? "warn" : "" }, v)));
  if (!m.jitter_hist) return;
  const e = m.jitter_hist.edges_us, labels = e.map(x => "<" + (x >= 1000 ? x / 1000 + "ms" : x + "µs")).concat([">" + e[e.length - 1] / 1000 + "ms"]);
  plot.bars($("jitter-hist"), labels, m.jitter_hist.counts, "wake-up jitter (ticks, log)");
  if (m.window) { S.compute.t.push(f.t); S.compute.lo.push(0); S.compute.hi.push(m.window.compute_max_us); }
}

// --- finger over the scene ---
function findTap(pred) { return S.taps.findIndex(pred); }
// The value a live parameter had at time t: its initial value, then its `set` events.
function paramAt(node, param, initial, t) {
  let v = initial;
  for (const e of S.events) if (e.event === "set" && e.node === node && e.param === param && e.t <= t) v = e.value;
  return v;
}
function heightColor(z, zmax) {
  const a = Math.max(-1, Math.min(1, z / zmax));
  return a >= 0 ? `rgb(${255 - 60 * a},${255 - 120 * a},${255 - 200 * a})` : `rgb(${255 + 200 * a},${255 + 120 * a},255)`;
}
function sceneDraw(t0, t1) {
  const c = $("scene"), sc = S.hello.scene || { kind: "none" }, g = S.hello.graph;
  const tnow = S.view ? t1 : S.t;
  let xi, yi, ci, xl, yl, background = null, xr = null, yr = null, note = "", fallback = false;
  if (sc.kind === "grid") {
    const src = inp => { const e = g.edges.find(e => e.to === sc.node && e.in === inp); return e ? findTap(t => t.node === e.from && t.port === e.out) : -1; };
    xi = src("velocity"); yi = src("load"); ci = findTap(t => t.port === "force"); xl = "velocity (cm/s)"; yl = "load (g)";
  }
  if (sc.kind === "grid" && (xi < 0 || yi < 0)) {
    // The grid's inputs were not recorded: the finger's position instead.
    const feed = inp => { const e = g.edges.find(e => e.to === sc.node && e.in === inp); return e ? `--tap ${e.from}.${e.out}` : ""; };
    note = `the velocity and load feeding ${sc.node} are not recorded (record them with ${feed("velocity")} ${feed("load")}): the finger's position instead; `;
    fallback = true;
  }
  if (sc.kind === "grid" && !fallback) {
    const k = paramAt(sc.node, "texture", sc.texture, tnow), grid = sc.grids[k] || sc.grids[0];
    const L = grid.loads_g, V = grid.velocities_cm_s;
    xr = plot.range(Math.min(V[0], 0), V[V.length - 1] * 1.25); yr = plot.range(Math.min(L[0], 0), L[L.length - 1] * 1.25);
    note = `texture ${k}: ${grid.name}; grid ${L.join("/")} g × ${V.join("/")} cm/s; `;
    background = (ctx, X, Y, r) => {
      ctx.strokeStyle = "#ccd"; ctx.lineWidth = r;
      for (const v of V) { ctx.beginPath(); ctx.moveTo(X(v), Y(yr[0])); ctx.lineTo(X(v), Y(yr[1])); ctx.stroke(); }
      for (const l of L) { ctx.beginPath(); ctx.moveTo(X(xr[0]), Y(l)); ctx.lineTo(X(xr[1]), Y(l)); ctx.stroke(); }
      const px = S.series[xi] && S.series[xi].last, py = S.series[yi] && S.series[yi].last;
      const xv = S.view ? sampleAt(S.series[xi], tnow) : px, yv = S.view ? sampleAt(S.series[yi], tnow) : py;
      if (xv === null || yv === null || xv === undefined || yv === undefined) return;
      const cell = (ax, x) => { let i = 0; while (i + 2 < ax.length && x > ax[i + 1]) i++; return ax.length > 1 ? [ax[i], ax[i + 1]] : [ax[0], ax[0]]; };
      const [v0, v1] = cell(V, xv), [l0, l1] = cell(L, yv);
      ctx.fillStyle = "#fde68a88"; ctx.fillRect(X(v0), Y(l1), X(v1) - X(v0), Y(l0) - Y(l1));
      ctx.fillStyle = "#d98200";
      for (const [v, l] of [[v0, l0], [v0, l1], [v1, l0], [v1, l1]]) ctx.fillRect(X(v) - 4 * r, Y(l) - 4 * r, 8 * r, 8 * r);
      S.cells = [[l0, v0], [l0, v1], [l1, v0], [l1, v1]];
    };
  } else {
    ci = -1;
    xi = findTap(t => t.port === "x" && g.nodes.some(n => n.name === t.node && n.type.startsWith("sim.user")));
    if (xi < 0) xi = findTap(t => t.port === "x");
    yi = findTap(t => t.port === "y" && t.node === (S.taps[xi] || {}).node);
    if (sc.kind !== "grid") ci = findTap(t => t.port === "intensity");
    xl = "x (m)"; yl = "y (m)";
    if (sc.kind === "mesh" && sc.maps.length) {
      const k = paramAt(sc.node, "scene", sc.scene, tnow), m = sc.maps[k] || sc.maps[0];
      xr = [m.x0, m.x1]; yr = [m.y0, m.y1];
      const zs = m.z_mm.filter(z => z !== null), zmax = Math.max(1e-9, ...zs.map(Math.abs));
      note = `scene ${k}: ${m.name}; heights ±${zmax.toFixed(2)} mm (brown up, blue down); `;
      background = (ctx, X, Y) => {
        const dx = (m.x1 - m.x0) / m.nx, dy = (m.y1 - m.y0) / m.ny;
        for (let j = 0; j < m.ny; j++) for (let i = 0; i < m.nx; i++) {
          const z = m.z_mm[j * m.nx + i];
          ctx.fillStyle = z === null ? "#eee" : heightColor(z, zmax);
          const x = m.x0 + i * dx, y = m.y0 + j * dy;
          ctx.fillRect(X(x), Y(y + dy), X(x + dx) - X(x) + 1, Y(y) - Y(y + dy) + 1);
        }
      };
    }
  }
  if (xi < 0 || yi < 0) { $("scene-note").textContent = "no finger position is tapped in this graph"; return; }
  const sx = S.series[xi], sy = S.series[yi], sci = ci >= 0 ? S.series[ci] : null;
  const pts = [];
  let bx = [Infinity, -Infinity], by = [Infinity, -Infinity], cr = [Infinity, -Infinity];
  const n = 150;
  for (let k = 0; k <= n; k++) {
    const t = t0 + (t1 - t0) * k / n;
    if (t > S.t && !S.view) break;
    const x = sampleAt(sx, t), y = sampleAt(sy, t), cv = sci ? sampleAt(sci, t) : 0;
    if (x === null || y === null) continue;
    pts.push([x, y, cv ?? 0]);
    bx = [Math.min(bx[0], x), Math.max(bx[1], x)]; by = [Math.min(by[0], y), Math.max(by[1], y)]; cr = [Math.min(cr[0], Math.abs(cv ?? 0)), Math.max(cr[1], Math.abs(cv ?? 0))];
  }
  if (!pts.length) return;
  const span = cr[1] - cr[0] || 1;
  for (const p of pts) p[2] = (Math.abs(p[2]) - cr[0]) / span;
  plot.trail(c, pts, xr || plot.range(bx[0], bx[1]), yr || plot.range(by[0], by[1]), xl, yl, background);
  $("scene-note").textContent = note + `${tapName(S.taps[xi])} × ${tapName(S.taps[yi])}` + (sci ? `; dots coloured by |${tapName(S.taps[ci])}| (blue low → red high)` : "") + "; the large dot is now";
}
function sampleAt(s, t) {
  let lo = 0, hi = s.t.length - 1;
  if (hi < 0) return null;
  while (lo < hi) { const m = (lo + hi + 1) >> 1; if (s.t[m] <= t) lo = m; else hi = m - 1; }
  return s.hi[lo] === null ? null : (s.lo[lo] + s.hi[lo]) / 2;
}

// --- graph ---
const esc = x => String(x).replace(/[&<>"']/g, c => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" })[c]);
function graphDraw(g) {
  const depth = {};
  g.nodes.forEach(n => depth[n.name] = 0);
  for (let pass = 0; pass < g.nodes.length; pass++)
    for (const e of g.edges) if (depth[e.to] < depth[e.from] + 1 && pass < g.nodes.length - 1) depth[e.to] = Math.min(depth[e.from] + 1, g.nodes.length);
  const cols = {}; g.nodes.forEach(n => (cols[depth[n.name]] = cols[depth[n.name]] || []).push(n));
  const W = 150, H = 46, pos = {};
  let maxRow = 0;
  for (const [d, ns] of Object.entries(cols)) ns.forEach((n, r) => { pos[n.name] = [10 + d * (W + 40), 10 + r * (H + 18)]; maxRow = Math.max(maxRow, r); });
  const width = 20 + (Math.max(...Object.keys(cols).map(Number)) + 1) * (W + 40), height = 20 + (maxRow + 1) * (H + 18);
  let svg = `<svg viewBox="0 0 ${width} ${height}" height="${height}">`;
  for (const e of g.edges) {
    const [x1, y1] = pos[e.from], [x2, y2] = pos[e.to];
    const a = [x1 + W, y1 + H / 2], b = [x2, y2 + H / 2];
    svg += `<path class="edge" d="M${a[0]},${a[1]} C${a[0] + 25},${a[1]} ${b[0] - 25},${b[1]} ${b[0]},${b[1]}"><title>${esc(e.from)}.${esc(e.out)} → ${esc(e.to)}.${esc(e.in)} (${e.rate} Hz)</title></path>`;
    svg += `<text class="edge-label" x="${(a[0] + b[0]) / 2 - 10}" y="${(a[1] + b[1]) / 2 - 2}">${plot.fmt(e.rate)}</text>`;
  }
  for (const n of g.nodes) {
    const [x, y] = pos[n.name];
    const why = (g.pruned.find(p => p.node === n.name) || {}).reason;
    svg += `<g class="node${n.in_plan ? "" : " pruned"}${n.guard ? " guard" : ""}"><rect x="${x}" y="${y}" width="${W}" height="${H}" rx="5"/><title>${esc(n.type)}${why ? " — left out: " + esc(why) : ""}</title>` +
      `<text x="${x + 6}" y="${y + 15}"><tspan font-weight="700">${esc(n.name)}</tspan></text><text x="${x + 6}" y="${y + 29}">${esc(n.type)}</text><text x="${x + 6}" y="${y + 41}">${plot.fmt(n.rate)} Hz${n.in_plan ? "" : " · left out"}</text></g>`;
  }
  $("graph").innerHTML = svg + "</svg>";
  const pr = $("pruned"); pr.textContent = "";
  if (!g.pruned.length) pr.append(el("li", {}, "the plan left nothing out"));
  for (const p of g.pruned) pr.append(el("li", {}, `left out: ${p.node} — ${p.reason}`));
}

// --- events ---
function eventShow(e) {
  S.events.push(e);
  let text = `${e.t.toFixed(3)} s (tick ${e.tick}) `;
  if (e.event === "set") { text += `${e.node}.${e.param} = ${e.value}`; steerFollow(e); }
  else if (e.event === "refused") text += `REFUSED by the node: ${e.node}.${e.param} = ${e.value}`;
  else if (e.event === "stop") { text += `stop: ${e.reason}`; S.ended = true; }
  else if (e.event === "gap") text += `gap: ${e.ticks} ticks of samples lost`;
  else text += e.event;
  logLine($("events"), text, e.event === "refused" || e.event === "gap" ? "err" : "");
  // A recorded session's changes under "Changes" (the stop's fade-outs are not the user's).
  if (S.recorded && (e.event === "set" || e.event === "refused") && !S.ended)
    logLine($("steer-log"), `at ${e.t.toFixed(3)} s: ${e.node}.${e.param} = ${e.value}` + (e.event === "refused" ? " (refused)" : ""), e.event === "refused" ? "err" : "ok");

}

// --- recorded sessions ---
function recordedInit(h) {
  const r = h.recording;
  $("traces-window").textContent = "(the whole session: choose the span to show with the sliders; min/max per 5 ms)";
  const from = el("input", { type: "range", id: "scrub-from", min: 0, max: r.seconds, step: r.seconds / 1000, value: 0 });
  const span = el("input", { type: "range", id: "scrub-span", min: Math.min(0.05, r.seconds), max: r.seconds, step: r.seconds / 1000, value: r.seconds });
  const upd = () => { const a = +from.value, w = +span.value; S.view = [a, Math.min(a + w, Math.max(r.seconds, a + 0.01))]; draw(); };
  from.oninput = upd; span.oninput = upd;
  $("traces-panel").insertBefore(el("div", { class: "row" }, "from", from, "span", span,
    el("span", { class: "small" }, `${r.seconds.toFixed(3)} s · stopped: ${r.stopped} · replay check: `),
    el("b", { id: "replay-check" }, r.replay.summary)), $("traces"));
  S.view = [0, r.seconds];
  $("drops").parentElement.style.display = "none";
  for (const n of r.notes || []) $("traces-panel").insertBefore(el("p", { class: "note" }, "⚠ " + n), $("traces"));
  for (const l of h.limiters) $(`limiter-${l.node}`).parentElement.after(el("div", { class: "small" }, "state over the shown span:"), el("canvas", { id: `timeline-${l.node}`, class: "timeline", width: 600, height: 18 }));
  $("compute").style.display = "none";
}
function replayShow(r) {
  S.replay = r;
  const b = $("replay-check");
  if (b) { b.textContent = (r.ok ? "✓ reproduced: " : "✗ ") + r.summary; b.className = r.ok ? "ok" : "bad"; }
}
const STATE_COLORS = { armed: "#1c8a3a", clamping: "#d98200", faulted: "#c0162b", fading: "#3566c4", faded: "#6b7280" };
function timelinesDraw() {
  if (!S.timelines || !S.view) return;
  const [t0, t1] = S.view;
  for (const l of S.timelines) {
    const c = $(`timeline-${l.node}`);
    if (!c) continue;
    const g = c.getContext("2d");
    g.clearRect(0, 0, c.width, c.height);
    for (const seg of l.segments) {
      const a = Math.max(seg.t0, t0), b = Math.min(seg.t1, t1);
      if (b <= a) continue;
      g.fillStyle = STATE_COLORS[seg.state] || "#999";
      g.fillRect((a - t0) / (t1 - t0) * c.width, 0, Math.max(1, (b - a) / (t1 - t0) * c.width), c.height);
    }
  }
}
function markers() {
  // Events on the time axis of every trace.
  if (!S.view) return;
  timelinesDraw();
  const [t0, t1] = S.view;
  S.taps.forEach((t, i) => {
    const c = $("canvas-" + i);
    if (!c || $("trace-" + i).style.display === "none") return;
    const g = c.getContext("2d");
    for (const e of S.events) {
      if (e.t < t0 || e.t > t1) continue;
      const x = (e.t - t0) / (t1 - t0) * c.width;
      g.strokeStyle = e.event === "set" ? "#1c8a3a" : "#c0162b";
      g.beginPath(); g.moveTo(x, 0); g.lineTo(x, c.height); g.stroke();
    }
  });
}
window.addEventListener("resize", requestDraw);
