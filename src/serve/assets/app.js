// plantwide live page: draws the flowsheet from /api/plant, polls /api/state for the faceplates
// and the clock, streams trend samples from /api/stream, and sends every action as one
// POST /api/command (the API is the page's only way in).
'use strict';

// The session token: in the page on 127.0.0.1 and ::1, in the address (?token=) beyond; every
// request sends it (commands are refused without it), the trend stream in its query.
const urlToken = new URLSearchParams(location.search).get('token');
const token = urlToken || document.querySelector('meta[name="plantwide-token"]').content;
const authHeaders = token ? { 'X-Plantwide-Token': token } : {};
const COLORS = ['#4fc3f7', '#ffb74d', '#81c784', '#e57373', '#ba68c8', '#fff176', '#4db6ac', '#f06292'];
const MAX_POINTS = 4000;
const MAX_PENS = 8;

// State the tests read: trend samples per pen, the last state.
const live = { plant: null, state: null, pens: [], data: {}, units: {} };
window.plantwide = live;

const $ = (id) => document.getElementById(id);

async function getJson(path) {
  const r = await fetch(path, { headers: authHeaders });
  if (!r.ok) throw new Error((await r.json()).error || r.statusText);
  return r.json();
}

async function send(cmd) {
  const r = await fetch('api/command', {
    method: 'POST',
    headers: Object.assign({ 'Content-Type': 'application/json' }, authHeaders),
    body: JSON.stringify(cmd),
  });
  const body = await r.json();
  const msg = $('message');
  if (r.ok) {
    msg.className = 'message';
    msg.textContent = JSON.stringify(cmd) + ' → at t = ' + fmt(body.at) + ' s';
  } else {
    msg.className = 'message error';
    msg.textContent = 'refused (' + r.status + '): ' + body.error;
  }
  refreshState();
  return r.ok;
}

function fmt(v) {
  if (v === null || v === undefined || Number.isNaN(v)) return '—';
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(4);
  return v.toPrecision(6);
}

function clockText(t) {
  const s = Math.floor(t);
  const hh = Math.floor(s / 3600), mm = Math.floor((s % 3600) / 60), ss = s % 60;
  const two = (n) => String(n).padStart(2, '0');
  return 't = ' + (t / 60).toFixed(2) + ' min (' + hh + ':' + two(mm) + ':' + two(ss) + ')';
}

// ---------------------------------------------------------------- flowsheet
const SVG = 'http://www.w3.org/2000/svg';
function el(name, attrs, parent, text) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  if (parent) parent.appendChild(e);
  return e;
}

function layout(plant) {
  const cols = Math.max(...plant.units.map((u) => u.col)) + 1;
  const rows = Math.max(...plant.units.map((u) => u.row)) + 1;
  const w = 900 / cols, h = 300 / rows;
  const pos = {};
  for (const u of plant.units) {
    const tall = u.shape === 'column';
    pos[u.name] = { x: 40 + u.col * w + w / 2 - 40, y: 20 + u.row * h + (tall ? 10 : h / 2 - 25), w: 80, h: tall ? Math.min(h - 20, 230) : 50, u };
  }
  return pos;
}

function drawUnit(svg, p) {
  const g = el('g', { class: 'unit', id: 'unit-' + p.u.name }, svg);
  const t = p.u.type, shape = p.u.shape;
  if (shape === 'column') {
    el('rect', { x: p.x + 20, y: p.y, width: 40, height: p.h, rx: 18, fill: '#b8c4cf', stroke: '#334', 'stroke-width': 2 }, g);
    for (let k = 1; k < 8; k++) {
      const y = p.y + (p.h * k) / 8;
      el('line', { x1: p.x + 22, x2: p.x + 58, y1: y, y2: y, stroke: '#667', 'stroke-dasharray': '4 3' }, g);
    }
  } else if (shape === 'source' || shape === 'sink') {
    const x = p.x + 10, y = p.y + 12;
    el('polygon', { points: `${x},${y} ${x + 45},${y} ${x + 60},${y + 13} ${x + 45},${y + 26} ${x},${y + 26}`, fill: shape === 'source' ? '#cfe3cf' : '#e3dccf', stroke: '#334', 'stroke-width': 1.5 }, g);
  } else if (shape === 'vessel') {
    el('rect', { x: p.x + 12, y: p.y, width: 56, height: 50, rx: 14, fill: '#c9d6c4', stroke: '#334', 'stroke-width': 2 }, g);
  } else {
    el('rect', { x: p.x + 10, y: p.y + 8, width: 60, height: 34, rx: 4, fill: '#d6cfc4', stroke: '#334', 'stroke-width': 1.5 }, g);
  }
  el('text', { x: p.x + 40, y: p.y + p.h + 13, 'text-anchor': 'middle', 'font-size': 11 }, g, p.u.name);
  el('text', { x: p.x + 40, y: p.y + p.h + 25, 'text-anchor': 'middle', 'font-size': 9, fill: '#556' }, g, t);
}

function drawFlowsheet(plant) {
  const svg = $('flowsheet');
  svg.innerHTML = '';
  const defs = el('defs', {}, svg);
  const m = el('marker', { id: 'arrow', markerWidth: 8, markerHeight: 8, refX: 7, refY: 4, orient: 'auto' }, defs);
  el('path', { d: 'M0,0 L8,4 L0,8 z', fill: '#223' }, m);
  const pos = layout(plant);
  for (const s of plant.streams) {
    const a = pos[s.from], b = pos[s.to];
    if (!a || !b) continue;
    // Ports spread down the unit's side in their order (a column's distillate above its bottoms).
    const port = (p, k, n) => p.y + (p.h * (k + 1)) / ((n || 1) + 1);
    const x1 = a.x + 70, y1 = port(a, s.from_port, s.from_ports), x2 = b.x + 10, y2 = port(b, s.to_port, s.to_ports);
    const xm = (x1 + x2) / 2;
    const d = x2 > x1 ? `M${x1},${y1} H${xm} V${y2} H${x2}` : `M${x1},${y1} H${x1 + 15} V${Math.max(y1, y2) + 70} H${x2 - 15} V${y2} H${x2}`;
    el('path', { d, fill: 'none', stroke: '#223', 'stroke-width': 2, 'marker-end': 'url(#arrow)' }, svg);
    el('text', { x: xm + 3, y: Math.min(y1, y2) + (y1 === y2 ? -4 : (Math.abs(y2 - y1) / 2)), 'font-size': 10, fill: '#224', id: 'stream-' + s.name }, svg, s.name);
  }
  for (const p of Object.values(pos)) drawUnit(svg, p);
  const count = {};
  for (const c of plant.controllers) {
    const home = pos[c.pv_unit] || pos[(c.drives[0] || {}).unit];
    if (!home) continue;
    const k = (count[home.u.name] = (count[home.u.name] || 0) + 1) - 1;
    const cx = home.x + 110 + 34 * Math.floor(k / 4), cy = home.y - 6 + 44 * (k % 4);
    const target = pos[(c.drives[0] || {}).unit];
    if (target) {
      el('line', { x1: cx, y1: cy, x2: target.x + 40, y2: target.y + target.h / 2, stroke: '#a33', 'stroke-dasharray': '3 3' }, svg);
    }
    el('line', { x1: cx, y1: cy, x2: home.x + 60, y2: home.y + Math.min(home.h / 2, 20 + 44 * (k % 4)), stroke: '#36a', 'stroke-dasharray': '3 3' }, svg);
    el('circle', { cx, cy, r: 14, fill: '#fff', stroke: '#333', 'stroke-width': 1.5 }, svg);
    el('text', { x: cx, y: cy + 3, 'text-anchor': 'middle', 'font-size': 7 }, svg, c.name.slice(0, 7));
    el('title', {}, svg.lastChild, c.name);
    el('text', { x: cx + 17, y: cy + 4, 'font-size': 9, fill: '#06c', id: 'bubble-' + c.name }, svg, '');
  }
}

function updateFlowsheet(values) {
  for (const c of live.plant.controllers) {
    const t = document.getElementById('bubble-' + c.name);
    if (t && c.pv) t.textContent = fmt(values[c.pv]);
  }
  for (const s of live.plant.streams) {
    const t = document.getElementById('stream-' + s.name);
    const f = values[s.name + '.F'];
    if (t && f !== undefined) t.textContent = s.name + ' ' + fmt(f * 60 / 1000) + ' kmol/min';
  }
}

// ---------------------------------------------------------------- faceplates
function faceplate(c) {
  const d = document.createElement('div');
  d.className = 'faceplate';
  d.id = 'fp-' + c.name;
  const unit = (p) => (p && live.units[p] ? ' ' + live.units[p] : '');
  d.innerHTML = `<div><span class="name">${c.name}</span> <span class="kind">${c.type}</span></div>
    <div class="bar"><div class="fill"></div><div class="mark"></div></div>
    <table>
      <tr><td class="k">PV</td><td class="pv" id="pv-${c.name}">—</td><td class="kind">${unit(c.pv)}</td></tr>
      <tr><td class="k">SP</td><td class="sp" id="spv-${c.name}">—</td><td class="kind">${unit(c.sp)}</td></tr>
      <tr><td class="k">OP</td><td class="op" id="op-${c.name}">—</td><td class="kind">${unit(c.op[0])}</td></tr>
    </table>
    <div class="modes">mode <span id="mode-${c.name}">—</span>
      <button id="auto-${c.name}">AUTO</button><button id="man-${c.name}">MAN</button></div>`;
  if (c.sp && !c.cascade) {
    d.insertAdjacentHTML('beforeend', `<div>SP <input id="sp-${c.name}" placeholder="value unit"><button id="spset-${c.name}">Set</button></div>`);
  }
  if (c.op_manual) {
    d.insertAdjacentHTML('beforeend', `<div>OP <input id="opm-${c.name}" placeholder="manual output"><button id="opset-${c.name}">Set</button></div>`);
  }
  const tune = document.createElement('div');
  tune.className = 'tune';
  const settings = Object.entries(c.settings || {}).filter(([, v]) => typeof v !== 'object');
  if (settings.length) {
    tune.insertAdjacentHTML('beforeend', '<div>' + settings.map(([k, v]) => `${k} ${v}`).join(' · ') + '</div>');
  }
  for (const p of c.tuning.slice(0, 4)) {
    const short = p.slice(c.name.length + 1);
    tune.insertAdjacentHTML('beforeend', `<div>${short} = <span data-path="${p}">—</span> <input data-set="${p}" placeholder="new"></div>`);
  }
  d.appendChild(tune);
  return d;
}

function bindFaceplate(c) {
  const click = (id, f) => { const b = $(id); if (b) b.onclick = f; };
  click('auto-' + c.name, () => send({ mode: { [c.name]: 'auto' } }));
  click('man-' + c.name, () => send({ mode: { [c.name]: 'manual' } }));
  click('spset-' + c.name, () => send({ set: { [c.sp]: $('sp-' + c.name).value } }));
  click('opset-' + c.name, () => send({ set: { [c.op_manual]: $('opm-' + c.name).value } }));
  for (const inp of $('fp-' + c.name).querySelectorAll('input[data-set]')) {
    inp.onkeydown = (e) => { if (e.key === 'Enter') send({ set: { [inp.dataset.set]: inp.value } }); };
  }
  if (!c.auto) { for (const id of ['auto-', 'man-']) { const b = $(id + c.name); if (b) b.disabled = true; } }
}

function updateFaceplates(values) {
  for (const c of live.plant.controllers) {
    const pv = c.pv ? values[c.pv] : NaN, sp = c.sp ? values[c.sp] : NaN, op = values[c.op[0]];
    $('pv-' + c.name).textContent = fmt(pv);
    $('spv-' + c.name).textContent = c.cascade ? 'cascade' : fmt(sp);
    $('op-' + c.name).textContent = fmt(op);
    const mode = c.cascade ? 'CAS' : c.auto ? (values[c.auto] >= 0.5 ? 'AUTO' : 'MAN') : 'AUTO';
    $('mode-' + c.name).textContent = mode;
    const a = $('auto-' + c.name), m = $('man-' + c.name);
    if (a) a.className = mode === 'AUTO' ? 'on' : '';
    if (m) m.className = mode === 'MAN' ? 'on' : '';
    const top = 1.5 * Math.max(Math.abs(pv) || 0, Math.abs(sp) || 0, 1e-12);
    const fp = $('fp-' + c.name);
    fp.querySelector('.fill').style.width = Math.max(0, Math.min(100, (100 * pv) / top)) + '%';
    fp.querySelector('.mark').style.left = Math.max(0, Math.min(100, (100 * sp) / top)) + '%';
    for (const s of fp.querySelectorAll('span[data-path]')) s.textContent = fmt(values[s.dataset.path]);
  }
}

// ---------------------------------------------------------------- trends
let stream = null;
function openStream() {
  if (stream) stream.close();
  const q = 'api/stream?paths=' + encodeURIComponent(live.pens.join(',')) + (urlToken ? '&token=' + encodeURIComponent(urlToken) : '');
  stream = new EventSource(q);
  stream.onmessage = (e) => {
    const s = JSON.parse(e.data);
    live.pens.forEach((p, k) => {
      const arr = (live.data[p] = live.data[p] || []);
      while (arr.length && arr[arr.length - 1][0] > s.t) arr.pop(); // a snapshot loaded: time went back
      if (!arr.length || arr[arr.length - 1][0] !== s.t) arr.push([s.t, s.v[k]]);
      if (arr.length > MAX_POINTS) arr.splice(0, arr.length - MAX_POINTS);
    });
    scheduleDraw();
  };
}

let drawPending = false;
function scheduleDraw() {
  if (!drawPending) { drawPending = true; requestAnimationFrame(() => { drawPending = false; drawTrend(); }); }
}

function drawTrend() {
  const cv = $('trend');
  const ctx = cv.getContext('2d');
  const W = cv.width, H = cv.height, L = 50, R = 10, T = 10, B = 24;
  ctx.fillStyle = '#0f1a24'; ctx.fillRect(0, 0, W, H);
  let t0 = Infinity, t1 = -Infinity;
  for (const p of live.pens) for (const [t] of live.data[p] || []) { t0 = Math.min(t0, t); t1 = Math.max(t1, t); }
  if (!(t1 > t0)) { t0 = 0; t1 = 1; }
  ctx.strokeStyle = '#2b3b4b'; ctx.fillStyle = '#9ab'; ctx.font = '10px sans-serif'; ctx.lineWidth = 1;
  for (let k = 0; k <= 5; k++) {
    const x = L + ((W - L - R) * k) / 5, y = T + ((H - T - B) * k) / 5;
    ctx.beginPath(); ctx.moveTo(x, T); ctx.lineTo(x, H - B); ctx.stroke();
    ctx.beginPath(); ctx.moveTo(L, y); ctx.lineTo(W - R, y); ctx.stroke();
    ctx.fillText(((t0 + ((t1 - t0) * k) / 5) / 60).toFixed(1), Math.min(x - 10, W - R - 40), H - 8);
  }
  ctx.fillText('time [min]', W - R - 52, T + 10);
  const legend = $('legend');
  legend.innerHTML = '';
  live.pens.forEach((p, k) => {
    const pts = live.data[p] || [];
    let lo = Infinity, hi = -Infinity;
    for (const [, v] of pts) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    // A pen at rest is drawn flat: its scale spans at least 0.1 % of its value.
    const span = Math.max(hi - lo, 1e-3 * Math.max(Math.abs(hi), Math.abs(lo)), 1e-12);
    const mid = (hi + lo) / 2; lo = mid - span / 2; hi = mid + span / 2;
    const pad = 0.05 * (hi - lo); lo -= pad; hi += pad;
    ctx.strokeStyle = COLORS[k % COLORS.length]; ctx.lineWidth = 1.6; ctx.beginPath();
    pts.forEach(([t, v], i) => {
      const x = L + ((W - L - R) * (t - t0)) / (t1 - t0), y = T + (H - T - B) * (1 - (v - lo) / (hi - lo));
      if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y);
    });
    ctx.stroke();
    const last = pts.length ? pts[pts.length - 1][1] : NaN;
    const item = document.createElement('span');
    item.className = 'pen';
    item.title = 'click to remove';
    item.innerHTML = `<span class="sw" style="background:${COLORS[k % COLORS.length]}"></span>${p} = ${fmt(last)} [${fmt(lo)} … ${fmt(hi)}] ${live.units[p] || ''}`;
    item.onclick = () => { live.pens.splice(k, 1); openStream(); scheduleDraw(); };
    legend.appendChild(item);
  });
}

// ---------------------------------------------------------------- state and controls
async function refreshState() {
  try {
    const s = await getJson('api/state');
    live.state = s;
    $('clock').textContent = clockText(s.time) + '  ×' + s.speed + (s.pending ? '  (' + s.pending + ' command(s) at the next step)' : '');
    const st = $('status');
    st.textContent = s.failure ? 'STOPPED' : s.running ? (s.behind ? 'RUNNING (behind)' : 'RUNNING') : 'PAUSED';
    st.className = 'status' + (s.failure ? ' failed' : s.running ? '' : ' paused');
    if (s.failure) { $('message').className = 'message error'; $('message').textContent = s.failure; }
    updateFaceplates(s.values);
    updateFlowsheet(s.values);
  } catch (e) {
    $('status').textContent = 'offline';
  }
}

async function refreshSnapshots() {
  const names = await getJson('api/snapshots');
  $('snap-list').innerHTML = names.map((n) => `<option>${n}</option>`).join('');
}

function eventOf() {
  const type = $('event-type').value, target = $('event-target').value, v = $('event-value').value, time = $('event-time').value;
  switch (type) {
    case 'step': return { type, path: target, to: v };
    case 'ramp': return { type, path: target, to: v, duration: time };
    case 'pulse': return { type, path: target, to: v, width: time };
    case 'sinusoid': return { type, path: target, amplitude: v, period: time };
    case 'valve_stuck': return v ? { type, path: target, to: v } : { type, path: target };
    case 'valve_repaired': return { type, path: target };
    default: return { type, unit: target };
  }
}

function bindControls() {
  $('pause').onclick = () => send({ pause: true });
  $('resume').onclick = () => send({ resume: true });
  $('step').onclick = () => send({ step: true });
  $('speed').onchange = () => send({ speed: Number($('speed').value) });
  $('snap-save').onclick = async () => { await send({ snapshot: $('snap-name').value }); refreshSnapshots(); };
  $('snap-load').onclick = () => send({ load: $('snap-list').value });
  $('input-set').onclick = () => send({ set: { [$('input-path').value]: $('input-value').value } });
  $('event-go').onclick = () => send({ event: eventOf() });
  $('trend-add').onclick = () => {
    const p = $('trend-path').value.trim();
    if (p && !live.pens.includes(p) && live.pens.length < MAX_PENS) { live.pens.push(p); openStream(); }
  };
}

async function main() {
  const plant = await getJson('api/plant');
  live.plant = plant;
  plant.paths.forEach((p, k) => { live.units[p] = plant.si_units[k]; });
  $('plant-name').textContent = 'plantwide — ' + plant.name;
  document.title = 'plantwide — ' + plant.name;
  // A tag's name trends its value (in SI, as every pen).
  plant.tags.forEach((t) => { live.units[t.name] = t.si_unit; });
  $('all-paths').innerHTML = plant.tags.map((t) => t.name).concat(plant.paths).map((p) => `<option value="${p}">`).join('');
  $('input-path').innerHTML = plant.inputs.map((i) => `<option>${i.path}</option>`).join('');
  drawFlowsheet(plant);
  const fps = $('faceplates');
  for (const c of plant.controllers) { fps.appendChild(faceplate(c)); bindFaceplate(c); }
  // `?pens=a,b` chooses the trend pens (default: every controller's measurement and setpoint).
  const asked = new URLSearchParams(location.search).get('pens');
  live.pens = (asked ? asked.split(',') : plant.trend).slice(0, MAX_PENS);
  bindControls();
  openStream();
  await refreshState();
  await refreshSnapshots();
  $('speed').value = String(live.state.speed);
  setInterval(refreshState, 500);
}

main();
