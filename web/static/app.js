// canfleet web: the page. Plain JavaScript and SVG (web/README.md says why): one WebSocket (/ws)
// brings a snapshot, then every update period the fleet's state and what is new (events, points);
// actions go to POST /api/action as control API requests in JSON.
"use strict";

const COLORS = ["#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00", "#00838f", "#ad1457", "#4e342e"];
const FAULT_KINDS = ["HEARTBEAT_LOSS", "BUS_OFF", "ERROR_PASSIVE", "RPDO_TIMEOUT", "DROP", "DELAY", "CORRUPT",
  "DUPLICATE", "PARTITION", "BABBLING_IDIOT", "KILL", "RESTART", "POWER_CYCLE"];

// Everything the page knows; tests read it (window.canfleet).
const fleet = {
  nodes: [], byKey: {}, diag: {}, buses: [], virtual: false, clockPairs: [], verdicts: {}, scenarios: [], events: [], series: {}, seriesNames: [], detail: null,
  retention: 600, now: 0,
  selected: null, plotted: [], span: 60, messages: 0, bytes: 0, connected: false,
};
window.canfleet = fleet;

const token = new URLSearchParams(location.hash.slice(1)).get("token");

// ---- data --------------------------------------------------------------------------------------
function apply(msg) {
  fleet.messages += 1;
  fleet.now = msg.now;
  fleet.retention = msg.retention_s;
  // Nodes come when they changed: keep them by key, list them by bus and node-ID.
  for (const n of msg.nodes) fleet.byKey[n.key] = n;
  fleet.nodes = Object.values(fleet.byKey).sort((a, b) => a.bus.localeCompare(b.bus) || a.id - b.id);
  if (msg.series) fleet.seriesNames = msg.series;
  if (msg.diag) for (const [key, d] of Object.entries(msg.diag)) { fleet.diag[key] = d; const r = rows.get(key); if (r) r.node = null; }
  fleet.buses = msg.buses;
  fleet.scenarios = msg.scenarios;
  for (const e of msg.events) {
    e.t = typeof e.time === "number" ? e.time : Date.parse(e.time) / 1000;  // ISO 8601, as `canfleet watch --json`
    fleet.events.push(e);
    // The latest verdict of each expectation (the Verdict topic): the scenario panel's rows.
    if (e.type === "verdict") fleet.verdicts[`${e.scenario}/${String(e.index).padStart(5, "0")}`] = e;
  }
  if (fleet.events.length > 5000) fleet.events.splice(0, fleet.events.length - 5000);
  fleet.virtual = fleet.buses.some((b) => b.mode === "virtual");
  for (const [t, name, value, simulated] of msg.points) {
    (fleet.series[name] ||= []).push([t, value, simulated]);
    // The buses' (wall, simulated) pairs: in virtual time every time on the page is drawn in
    // simulated seconds, those without one of their own (events, polled objects) by interpolation.
    if (simulated >= 0 && name.startsWith("bus:") && name.endsWith("/load")) {
      const last = fleet.clockPairs[fleet.clockPairs.length - 1];
      if (!last || t > last[0]) fleet.clockPairs.push([t, simulated]);
      if (fleet.clockPairs.length > 2000) fleet.clockPairs.splice(0, 1000);
    }
  }
  const oldest = fleet.now - fleet.retention;
  for (const points of Object.values(fleet.series)) {
    let drop = 0;
    while (drop < points.length && points[drop][0] < oldest) drop++;
    if (drop) points.splice(0, drop);
  }
  scheduleRender();
}

function connect() {
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`);
  ws.onopen = () => { fleet.connected = true; fleet.ws = ws; setLink(); subscribe(); };
  ws.onmessage = (ev) => { fleet.bytes += ev.data.length; apply(JSON.parse(ev.data)); };
  ws.onclose = () => { fleet.connected = false; setLink(); setTimeout(connect, 1000); };
}

// The server sends the points of the plotted series only (bus statistics always).
function subscribe() {
  if (fleet.ws && fleet.ws.readyState === WebSocket.OPEN) fleet.ws.send(JSON.stringify({ plot: fleet.plotted }));
}

// The selected node in full (its I/O, EMCY history), asked for once a second while it is shown.
async function refreshDetail() {
  if (fleet.selected) {
    try {
      const res = await fetch("/api/node?key=" + fleet.selected);
      const detail = await res.json();
      const emcys = detail && detail.emcy ? detail.emcy.length : 0;
      if (detail && detail.summary && detail.summary.name && fleet.info && fleet.info.actions &&
          (fleet.lastRead1003 !== fleet.selected + "/" + emcys)) {
        fleet.lastRead1003 = fleet.selected + "/" + emcys;
        read1003(detail.summary.name);
      }
      fleet.detail = detail;
      scheduleRender();
    } catch (e) { /* the next try */ }
  }
  setTimeout(refreshDetail, 1000);
}

function setLink() {
  const link = document.getElementById("link");
  link.textContent = fleet.connected ? "live" : "disconnected";
  link.className = "link " + (fleet.connected ? "up" : "down");
}

async function action(body) {
  const headers = { "Content-Type": "application/json" };
  if (token) headers.Authorization = "Bearer " + token;
  const res = await fetch("/api/action", { method: "POST", headers, body: JSON.stringify(body) });
  return res.json();
}

// ---- rendering -----------------------------------------------------------------------------------
let pending = false;
function scheduleRender() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => { pending = false; render(); });
}

function el(tag, attrs = {}, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}
function svgEl(tag, attrs = {}, text) {
  const e = document.createElementNS("http://www.w3.org/2000/svg", tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}
const nodeKey = (n) => `${n.bus}:${n.id}`;
const nodeLabel = (bus, id) => {
  const n = fleet.nodes.find((x) => x.bus === bus && x.id === id);
  return n && n.name ? n.name : `${bus} #${id}`;
};

function renderScenario() {
  const s = fleet.scenarios.find((x) => x.alive) || fleet.scenarios[0];
  document.getElementById("scenario-line").textContent = s
    ? `${s.scenario} (${s.source}), cycle ${s.cycle}, ${s.running ? "running" : "done"}: ${s.passed} passed, ` +
      `${s.failed} failed, ${s.skipped} skipped, ${s.pending} pending${s.step ? "; step " + s.step : ""}` : "(none on the domain)";
  const body = document.querySelector("#verdicts tbody");
  const rows = Object.keys(fleet.verdicts).sort().map((k) => {
    const v = fleet.verdicts[k];
    const tr = el("tr", { "data-verdict": v.name || String(v.index), "data-result": v.result });
    tr.append(el("td", {}, v.scenario), el("td", {}, String(v.cycle)), el("td", {}, v.name || `#${v.index}`),
      el("td", { class: "verdict-" + v.result }, v.result), el("td", {}, v.text));
    return tr;
  });
  body.replaceChildren(...rows);
}

function render() {
  renderScenario();
  renderHeader();
  renderOverview();
  renderBuses();
  renderDetail();
  renderTimeline();
  renderPlotPicker();
  renderPlot();
  renderFaults();
}

function renderHeader() {
  const s = fleet.scenarios.find((x) => x.alive) || fleet.scenarios[0];
  document.getElementById("scenario").textContent = s
    ? `${s.scenario}: ${s.passed} passed, ${s.failed} failed, ${s.pending} pending${s.step ? " · " + s.step : ""}` : "";
  const virtual = fleet.buses.find((b) => b.mode === "virtual");
  document.getElementById("clock").textContent = virtual
    ? `virtual time ${virtual.simulated_s.toFixed(1)} s · ${virtual.factor.toFixed(1)}x real time`
    : new Date(fleet.now * 1000).toLocaleTimeString();
}

// Rows are kept by node: a node's cells are rebuilt only when its summary changed (the server sends
// it only then), the age of its last status every frame; 500 nodes stay cheap to show.
const rows = new Map();
function renderOverview() {
  const body = document.querySelector("#overview tbody");
  let added = false;
  for (const n of fleet.nodes) {
    let row = rows.get(n.key);
    if (!row) {
      row = { tr: el("tr", { "data-node": n.key, "data-name": n.name }), node: null, age: null, selected: null };
      row.tr.onclick = () => { fleet.selected = n.key; fleet.detail = null; refreshNow(); scheduleRender(); };
      rows.set(n.key, row);
      added = true;
    }
    if (row.node !== n) {
      row.node = n;
      row.tr.classList.toggle("faulted", n.faulted);
      row.tr.classList.toggle("stale", n.stale || !n.alive);
      const d = fleet.diag[n.key];
      const cells = [n.bus, n.id, n.name, n.device, n.nmt, n.controller, n.tec, n.rec, n.error_register + "h",
        n.heartbeat_ms ? n.heartbeat_ms + " ms" : "off", "",
        n.last_emcy ? `${n.last_emcy.code}h (${n.last_emcy.register}h)` : "",
        d && d.hb_min_ms !== null ? `${fmt(d.hb_min_ms)}–${fmt(d.hb_max_ms)} ms ±${fmt(d.hb_jitter_ms ?? 0)}` : "",
        d && d.sdo_min_ms !== null ? `${fmt(d.sdo_min_ms)}–${fmt(d.sdo_max_ms)} ms (${d.sdo_responses})` : "",
        d ? String(d.bootups) : ""];
      row.tr.replaceChildren(...cells.map((c, i) => {
        const td = el("td", {}, String(c));
        if (i === 4) { td.className = "state-" + n.nmt; td.setAttribute("data-field", "nmt"); }
        if (i === 8) td.setAttribute("data-field", "error-register");
        if (i === 12) td.setAttribute("data-field", "heartbeat-period");
        if (i === 13) td.setAttribute("data-field", "sdo-time");
        return td;
      }));
      row.age = row.tr.children[10];
    }
    row.age.textContent = n.alive ? Math.max(0, fleet.now - n.last_sample).toFixed(1) + " s ago" : "gone";
    const selected = fleet.selected === n.key;
    if (row.selected !== selected) { row.tr.classList.toggle("selected", selected); row.selected = selected; }
  }
  if (added) body.replaceChildren(...fleet.nodes.map((n) => rows.get(n.key).tr));
}

// The simulated time of a wall-clock time (virtual time), from the buses' pairs.
function simOf(wall) {
  const pairs = fleet.clockPairs;
  if (!pairs.length) return wall;
  let i = pairs.length - 1;
  while (i > 0 && pairs[i][0] > wall) i--;
  const [w0, s0] = pairs[i];
  const next = pairs[i + 1] || pairs[i - 1];
  const factor = next && next[0] !== w0 ? (next[1] - s0) / (next[0] - w0) : 1;
  return Math.max(0, s0 + (wall - w0) * factor);
}
// A time on the page's axes: simulated seconds in virtual time, else wall-clock seconds.
const axis = (wall, simulated) => !fleet.virtual ? wall : simulated >= 0 ? simulated : simOf(wall);
const axisUnit = () => fleet.virtual ? "s simulated" : "s";
const timeText = (wall) => fleet.virtual ? `t=${simOf(wall).toFixed(3)} s` : new Date(wall * 1000).toLocaleTimeString();

function lineChart(svg, series, opts) {
  // series: [{points: [[t, v]], color, name}]; x: time from t0 to t1
  const w = svg.clientWidth || 500, h = Number(svg.getAttribute("height"));
  svg.replaceChildren();
  const pad = { l: 40, r: 8, t: 6, b: 16 };
  // From the first point kept (at least 10 s back), at most `span` back: a young fleet fills the chart.
  const first = Math.min(...series.flatMap((s) => s.points.map((p) => axis(p[0], p[2]))), Infinity);
  const t1 = axis(fleet.now, -1), t0 = Math.min(t1 - 10, Math.max(opts.span ? t1 - opts.span : -Infinity, first));
  let lo = Infinity, hi = -Infinity;
  for (const s of series) for (const p of s.points) if (axis(p[0], p[2]) >= t0) { lo = Math.min(lo, p[1]); hi = Math.max(hi, p[1]); }
  if (!isFinite(lo)) { lo = 0; hi = 1; }
  if (opts.zero) lo = Math.min(lo, 0);
  if (hi === lo) hi = lo + 1;
  const x = (t) => pad.l + (t - t0) / (t1 - t0) * (w - pad.l - pad.r);
  const y = (v) => h - pad.b - (v - lo) / (hi - lo) * (h - pad.t - pad.b);
  svg.appendChild(svgEl("line", { x1: pad.l, y1: h - pad.b, x2: w - pad.r, y2: h - pad.b, stroke: "#ccd" }));
  svg.appendChild(svgEl("text", { x: 2, y: pad.t + 8 }, fmt(hi)));
  svg.appendChild(svgEl("text", { x: 2, y: h - pad.b }, fmt(lo)));
  svg.appendChild(svgEl("text", { x: w - pad.r - 110, y: h - 3, "data-axis": axisUnit() }, `last ${Math.round(t1 - t0)} ${axisUnit()}`));
  if (!isFinite(t0)) return;
  for (const s of series) {
    // Hold the last value up to now (series kept on change only: controller states, polled objects).
    const held = s.points.map((p) => [axis(p[0], p[2]), p[1]]);
    if (held.length) held.push([t1, held[held.length - 1][1]]);
    const pts = held.filter((p) => p[0] >= t0).map((p) => `${x(p[0]).toFixed(1)},${y(p[1]).toFixed(1)}`);
    if (pts.length) svg.appendChild(svgEl("polyline", { points: pts.join(" "), fill: "none", stroke: s.color, "stroke-width": 1.5, "data-series": s.name }));
  }
}
const fmt = (v) => Math.abs(v) >= 1000 ? v.toFixed(0) : Number(v.toPrecision(4)).toString();

function renderBuses() {
  const box = document.getElementById("buses");
  for (const b of fleet.buses) {
    let div = box.querySelector(`[data-bus="${b.name}"]`);
    if (!div) {
      div = el("div", { class: "bus", "data-bus": b.name });
      div.append(el("div", { class: "summary" }), svgEl("svg", { width: "100%", height: "90" }));
      box.appendChild(div);
    }
    const loads = (fleet.series[`bus:${b.name}/load`] || []).map((p) => p[1]);
    const peak = loads.length ? Math.max(...loads) : 0;
    div.querySelector(".summary").textContent =
      `${b.name}: ${(b.bitrate / 1000) || "?"} kbit/s, load ${fmt(b.load ?? 0)} % (peak ${fmt(peak)} %), ${fmt(b.fps ?? 0)} frames/s, ` +
      `${b.error_frames ?? 0} error frames, ${b.nodes ?? 0} ports` + (b.faults.length ? `, ${b.faults.length} fault(s)` : "");
    lineChart(div.querySelector("svg"), [
      { name: `bus:${b.name}/load`, color: COLORS[0], points: fleet.series[`bus:${b.name}/load`] || [] },
    ], { span: fleet.span, zero: true });
  }
}

let refreshNow = () => {};

// The node's pre-defined error field (1003h, CiA 301 §7.5.2.5), read by SDO through the control API
// when the node is selected or its EMCY count changes.
async function read1003(name) {
  const read = async (sub, type) => {
    const r = await action({ sdo_read: { node: name, index: 0x1003, subindex: sub, type } });
    if (!r.ok) throw new Error(r.error);
    return r.response.sdo.text;
  };
  try {
    const count = Number(await read(0, "u8"));
    const entries = [];
    for (let sub = 1; sub <= Math.min(count, 16); sub++) entries.push(await read(sub, "u32"));
    fleet.errorField = { name, entries, error: "" };
  } catch (e) {
    fleet.errorField = { name, entries: [], error: e.message };
  }
  scheduleRender();
}
function renderDetail() {
  const box = document.getElementById("detail");
  const d = fleet.detail && fleet.detail.summary && nodeKey(fleet.detail.summary) === fleet.selected ? fleet.detail : null;
  const n = d ? { ...d, ...d.summary } : null;
  document.getElementById("detail-title").textContent = n ? `${n.name || n.bus + " #" + n.id} (${n.device})` : "(click a row)";
  box.replaceChildren();
  if (!n) return;
  if (n.diag) box.appendChild(el("p", { class: "muted" }, `heartbeats ${n.diag.heartbeats} (period ${fmt(n.diag.hb_min_ms ?? 0)}–${fmt(n.diag.hb_max_ms ?? 0)} ms, jitter ${fmt(n.diag.hb_jitter_ms ?? 0)} ms), boot-ups ${n.diag.bootups}, SDO answers ${n.diag.sdo_responses} in ${fmt(n.diag.sdo_min_ms ?? 0)}–${fmt(n.diag.sdo_max_ms ?? 0)} ms (${n.diag.sdo_aborts} aborts), EMCYs ${n.diag.emcys}`));
  box.appendChild(el("p", { class: "muted" }, `uptime ${n.uptime_s.toFixed(0)} s, RPDOs ${n.rpdo}, TPDOs ${n.tpdo}; heartbeat consumers: ${n.consumers.map((c) => `#${c.node} ${c.time_ms} ms ${c.state}`).join(", ") || "none"}`));
  const emcy = el("ol", { class: "emcy" });
  for (const e of n.emcy.slice().reverse()) emcy.appendChild(el("li", {}, `${timeText(e.time)} ${e.code}h register ${e.register}h data ${e.data}`));
  box.append(el("div", {}, n.emcy.length ? "EMCY history (newest first):" : "no EMCY"), emcy);
  const io = el("table", { class: "io" });
  io.appendChild(el("tr")).append(el("th", {}, "signal"), el("th", {}, "value"), el("th", {}, ""));
  for (const v of [...n.inputs, ...n.outputs]) {
    const tr = el("tr");
    tr.append(el("td", {}, v.name), el("td", {}, v.text || `${fmt(v.value)} ${v.unit}`));
    const td = el("td");
    const b = el("button", {}, "plot");
    b.onclick = () => { addPlot(`io:${n.bus}:${n.id}/${v.name}`); };
    td.appendChild(b);
    tr.appendChild(td);
    io.appendChild(tr);
  }
  const ef = fleet.errorField;
  const efText = !ef || ef.name !== n.name ? "1003h: reading..." : ef.error ? `1003h: ${ef.error}`
    : `1003h: ${ef.entries.length} error(s)${ef.entries.length ? ": " + ef.entries.map((v) => "0x" + Number(v).toString(16).toUpperCase().padStart(8, "0")).join(", ") : ""}`;
  box.appendChild(el("p", { class: "error-field", "data-field": "1003h" }, efText));
  const scroll = el("div", { class: "scroll" });
  scroll.appendChild(io);
  box.appendChild(scroll);
}

function eventText(e) {
  const who = e.node ? (e.name || `${e.bus} #${e.node}`) : e.bus;
  switch (e.type) {
    case "emcy": return `${who} EMCY ${e.text || e.code}`;
    case "fault": return `${e.bus} fault ${e.action} ${e.kind}${e.target_node ? " on " + nodeLabel(e.bus, e.target_node) : ""}`;
    case "verdict": return `verdict ${e.result} ${e.name || ""}: ${e.text}`;
    default: return `${who} ${e.type} ${e.from ?? ""} → ${e.to ?? ""}`;
  }
}

function renderTimeline() {
  const svg = document.getElementById("timeline");
  const w = svg.clientWidth || 800, h = Number(svg.getAttribute("height"));
  svg.replaceChildren();
  const lanes = [...new Set(fleet.events.map((e) => e.bus || "fleet"))].sort();
  const t1 = axis(fleet.now, -1);
  const first = Math.min(...fleet.events.map((e) => axis(e.t, -1)), Infinity);
  const t0 = Math.min(t1 - 10, Math.max(fleet.span ? t1 - fleet.span : -Infinity, first));
  const x = (t) => 60 + (t - t0) / (t1 - t0) * (w - 70);
  const laneH = Math.max(14, (h - 16) / Math.max(1, lanes.length));
  lanes.forEach((lane, i) => {
    svg.appendChild(svgEl("text", { x: 4, y: 12 + i * laneH + laneH / 2 }, lane));
    svg.appendChild(svgEl("line", { x1: 60, x2: w - 10, y1: 8 + (i + 0.5) * laneH, y2: 8 + (i + 0.5) * laneH, stroke: "#eef" }));
  });
  const kindColor = { emcy: "#c62828", fault: "#6a1b9a", verdict: "#1565c0", nmt: "#ef6c00", controller: "#00838f" };
  for (const e of fleet.events) {
    const et = axis(e.t, -1);
    if (et < t0) continue;
    const lane = lanes.indexOf(e.bus || "fleet");
    const c = svgEl("circle", { cx: x(et), cy: 8 + (lane + 0.5) * laneH, r: 4, fill: kindColor[e.type] || "#78909c", "data-type": e.type });
    c.appendChild(svgEl("title", {}, eventText(e)));
    svg.appendChild(c);
  }
  const list = document.getElementById("events");
  list.replaceChildren();
  for (const e of fleet.events.slice(-60).reverse()) {
    list.appendChild(el("li", { class: e.type, "data-type": e.type }, `${timeText(e.t)} ${eventText(e)}`));
  }
}

function renderPlotPicker() {
  const pick = document.getElementById("series-pick");
  const names = fleet.seriesNames.filter((n) => !n.startsWith("sdo:"));
  if (pick.options.length === names.length) return;
  const chosen = pick.value;
  pick.replaceChildren(...names.map((n) => el("option", { value: n }, n)));
  if (names.includes(chosen)) pick.value = chosen;
}

function addPlot(name) {
  if (name && !fleet.plotted.includes(name)) fleet.plotted.push(name);
  subscribe();
  scheduleRender();
}

function renderPlot() {
  const series = fleet.plotted.map((name, i) => ({ name, color: COLORS[i % COLORS.length], points: fleet.series[name] || [] }));
  lineChart(document.getElementById("plot"), series, { span: fleet.span });
  const legend = document.getElementById("plot-legend");
  legend.replaceChildren(...series.map((s) => {
    const last = s.points.length ? s.points[s.points.length - 1][1] : undefined;
    const span = el("span", { "data-series": s.name }, `${s.name} ${last === undefined ? "" : "= " + fmt(last)}`);
    span.style.color = s.color;
    return span;
  }));
}

// Objects plotted by SDO upload through the control API, once a second each (the page's own
// polling: "sdo:quad-5/1017h.0").
const polled = new Map();
function addObject(node, index, sub, type) {
  const name = `sdo:${node}/${index.toString(16).toUpperCase().padStart(4, "0")}h.${sub}`;
  if (!polled.has(name)) {
    polled.set(name, { node, index, sub, type: type || "u32" });
    if (!fleet.seriesNames.includes(name)) fleet.seriesNames = [...fleet.seriesNames, name].sort();
  }
  addPlot(name);
  return name;
}
async function pollObjects() {
  for (const [name, o] of polled) {
    if (!fleet.plotted.includes(name)) continue;
    try {
      const r = await action({ sdo_read: { node: o.node, index: o.index, subindex: o.sub, type: o.type } });
      if (r.ok) (fleet.series[name] ||= []).push([fleet.now, Number(r.response.sdo.text), -1]);
    } catch (e) { /* the next round */ }
  }
  scheduleRender();
  setTimeout(pollObjects, 1000);
}

function plotCsv() {
  const rows = ["time_s,series,value,simulated_s"];
  for (const name of fleet.plotted) for (const [t, v, sim] of fleet.series[name] || []) rows.push(`${t},${name},${v},${sim < 0 ? "" : sim}`);
  const a = el("a", { href: URL.createObjectURL(new Blob([rows.join("\n") + "\n"], { type: "text/csv" })), download: "canfleet-plot.csv" });
  a.click();
  return rows.length - 1;
}

function renderFaults() {
  const nodeSel = document.getElementById("fault-node");
  const names = fleet.nodes.map((n) => n.name).filter(Boolean);
  if (nodeSel.options.length !== names.length + 1) {
    const chosen = nodeSel.value;
    nodeSel.replaceChildren(el("option", { value: "" }, "(node)"), ...names.map((n) => el("option", { value: n }, n)));
    nodeSel.value = chosen;
  }
  const list = document.getElementById("faults");
  list.replaceChildren();
  for (const b of fleet.buses) {
    for (const f of b.faults) {
      const li = el("li", { "data-fault": f.id }, `#${f.id} ${f.kind} on ${f.node ? nodeLabel(b.name, f.node) : b.name} `);
      const clear = el("button", {}, "clear");
      clear.onclick = async () => showResult(await action({ fault_clear: { fault_id: f.id } }));
      li.appendChild(clear);
      list.appendChild(li);
    }
  }
}

function showResult(r) {
  const p = document.getElementById("fault-result");
  p.textContent = r.ok ? (r.response?.fault_injected?.summary || r.response?.done?.detail || "done") : r.error;
  p.className = r.ok ? "muted" : "error";
  fleet.lastResult = r;
}

// ---- controls ----------------------------------------------------------------------------------
function setup() {
  document.getElementById("fault-kind").replaceChildren(...FAULT_KINDS.map((k) => el("option", { value: k }, k.toLowerCase().replace(/_/g, "-"))));
  document.getElementById("fault-form").onsubmit = async (ev) => {
    ev.preventDefault();
    let options = {};
    const text = document.getElementById("fault-options").value.trim();
    try { if (text) options = JSON.parse(text); } catch (e) { return showResult({ ok: false, error: "options: " + e.message }); }
    const spec = { kind: document.getElementById("fault-kind").value, ...options };
    const node = document.getElementById("fault-node").value;
    if (node) spec.node = node;
    showResult(await action({ fault_inject: spec }));
  };
  document.getElementById("plot-add").onclick = () => addPlot(document.getElementById("series-pick").value);
  document.getElementById("plot-clear").onclick = () => { fleet.plotted = []; subscribe(); scheduleRender(); };
  document.getElementById("plot-csv").onclick = plotCsv;
  for (const b of document.querySelectorAll(".zoom button")) b.onclick = () => { fleet.span = Number(b.dataset.span); scheduleRender(); };
  document.getElementById("timeline").addEventListener("wheel", (ev) => {
    ev.preventDefault();
    fleet.span = Math.max(5, Math.round((fleet.span || fleet.retention) * (ev.deltaY > 0 ? 1.25 : 0.8)));
    scheduleRender();
  });
  window.canfleetActions = { action, addPlot, addObject, plotCsv };
  document.getElementById("object-add").onclick = () => {
    const [node, index, sub, type] = document.getElementById("object-pick").value.trim().split(/\s+/);
    if (node && index) addObject(node, parseInt(index, 16), Number(sub || 0), type);
  };
  pollObjects();
  fetch("/api/info").then((r) => r.json()).then((info) => { fleet.info = info; });
  refreshNow = () => { fetch("/api/node?key=" + fleet.selected).then((r) => r.json()).then((d) => { fleet.detail = d; scheduleRender(); }); };
  connect();
  refreshDetail();
}
setup();
