// The text panels: run header, joint list, loop numbers, devices, fault log.

import { el, fmt, fmtInt, isNum, jointUnit, setText } from './format.js';

const PHASES = {
  configure: 'configure',
  start_ramp: 'start ramp',
  motion: 'motion',
  stop_ramp: 'stop ramp',
  ended: 'ended',
};

export function showInfo(info) {
  setText('robot-name', info.robot || 'robot');
  const parts = [];
  if (info.backend) parts.push(`${info.backend} backend`);
  if (isNum(info.rate_hz)) parts.push(`${info.rate_hz} Hz`);
  if (info.replay && info.backend !== 'replay') parts.push('replay');
  setText('robot-backend', parts.join(' · '));
  document.title = `${info.robot || 'robot'} · animrt dashboard`;
}

export function showPhase(state) {
  const phase = document.getElementById('phase');
  const p = typeof state.phase === 'string' ? state.phase : '';
  phase.dataset.phase = p;
  setText('phase', PHASES[p] || p || '–');
  setText('run-time', fmt(state.t_s, 2, ' s'));
}

// The motion source from /api/info with the state's live part.
export function showMotion(info, state) {
  const m = (info && info.motion) || {};
  const live = (state && state.motion) || {};
  const manual = state && state.manual && state.manual.on;
  let text = [m.kind, m.name].filter(Boolean).join(' ') || 'motion';
  if (m.kind === 'gait' || isNum(live.speed_mps) || isNum(live.turn_rps)) {
    if (isNum(live.speed_mps)) text += ` · speed ${live.speed_mps.toFixed(2)} m/s`;
    if (isNum(live.turn_rps)) text += ` · turn ${live.turn_rps.toFixed(2)} rad/s`;
  }
  if (isNum(live.position_s)) {
    // A show's position is its playhead, out of the show's length; any
    // other motion's is the time into the run's --duration.
    const of = m.show ? live.duration_s : m.duration_s;
    text += ` · ${m.show ? 'show ' : ''}at ${live.position_s.toFixed(1)} s`;
    if (isNum(of)) text += ` of ${of.toFixed(1)} s`;
  }
  if (live.playing === false && state.phase === 'motion' && !manual) text += ' · paused';
  if (manual) text = `manual (was: ${text})`;
  setText('motion-source', text);
}

export class JointList {
  constructor(table, joints, onSelect) {
    this.body = table.tBodies[0];
    this.rows = new Map();
    this.joints = new Map();
    this.onSelect = onSelect;
    for (const j of joints) {
      if (!j || typeof j.name !== 'string') continue;
      this.joints.set(j.name, j);
      const cells = {
        cmd: el('td', { class: 'cmd', 'data-field': 'cmd', text: '–' }),
        meas: el('td', { class: 'meas', 'data-field': 'meas', text: '–' }),
        vel: el('td', { class: 'vel', 'data-field': 'vel', text: '–' }),
      };
      const row = el('tr', { 'data-joint': j.name }, el('td', { class: 'name', text: j.name }), cells.cmd, cells.meas, cells.vel);
      row.addEventListener('click', () => this.select(j.name));
      this.body.append(row);
      this.rows.set(j.name, { row, cells });
    }
  }

  select(name) {
    for (const [n, r] of this.rows) r.row.classList.toggle('selected', n === name);
    this.selected = name;
    setText('selected-joint', name);
    this.onSelect(name);
  }

  update(joints) {
    if (!Array.isArray(joints)) return;
    for (const j of joints) {
      const r = j && this.rows.get(j.name);
      if (!r) continue;
      const u = jointUnit(this.joints.get(j.name));
      const set = (cell, v, unit) => {
        const text = isNum(v) ? (v * u.scale).toFixed(1) + unit : '–';
        if (cell.textContent !== text) cell.textContent = text;
        if (isNum(v)) cell.dataset.value = String(v);
      };
      set(r.cells.cmd, j.cmd, u.pos);
      set(r.cells.meas, j.meas, u.pos);
      set(r.cells.vel, j.vel, u.vel);
    }
  }
}

export function showLoop(loop) {
  if (!loop) return;
  const trio = (o) => (o ? `${fmt(o.p50, 3)} / ${fmt(o.p99, 3)} / ${fmt(o.max, 3)} ms` : '–');
  setText('loop-rate', fmt(loop.rate_hz, 1, ' Hz'));
  setText('loop-cycles', fmtInt(loop.cycles));
  setText('loop-period', trio(loop.period_ms));
  setText('loop-jitter', trio(loop.jitter_ms));
  setText('loop-overruns', fmtInt(loop.overruns));
  setText('loop-skipped', fmtInt(loop.skipped));
  const late = loop.late && typeof loop.late === 'object' ? Object.entries(loop.late) : [];
  setText('loop-late', late.length ? late.map(([bus, n]) => `${bus} ${fmtInt(n)}`).join(', ') : '–');
}

function faultText(f) {
  if (f == null) return '';
  if (typeof f === 'string') return f;
  const t = isNum(f.t_s) ? `${f.t_s.toFixed(2)} s: ` : '';
  return t + (f.text || f.kind || JSON.stringify(f));
}

const COUNTERS = ['transactions', 'timeouts', 'crc', 'protocol', 'hardware', 'exceptions'];
// Device health as read (null: the device or its bus does not report it).
const HEALTH = [
  ['temperature_c', (v) => `${v.toFixed(0)} °C`],
  ['current_a', (v) => `${v.toFixed(2)} A`],
  ['voltage_v', (v) => `${v.toFixed(1)} V`],
  ['torque_nm', (v) => `${v.toFixed(2)} Nm`],
  ['error_bits', (v) => `0x${v.toString(16).padStart(2, '0')}`],
];

// A device's temperature and current over the last TREND_S seconds, drawn
// as two lines in one small canvas, each scaled to its own range.
const TREND_S = 10;
const TREND_LINES = [['temperature_c', '#ff7a7a', '°C'], ['current_a', '#7ab4ff', 'A']];

class Trend {
  constructor() {
    this.canvas = el('canvas', { class: 'spark', width: 96, height: 24 });
    this.points = [];  // [seconds, temperature, current]
  }

  add(d) {
    const t = performance.now() / 1000;
    if (!TREND_LINES.some(([k]) => isNum(d[k]))) return;
    this.points.push([t, ...TREND_LINES.map(([k]) => (isNum(d[k]) ? d[k] : null))]);
    while (this.points.length && this.points[0][0] < t - TREND_S) this.points.shift();
    this.draw(t);
  }

  draw(now) {
    const c = this.canvas;
    const g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    const titles = [];
    TREND_LINES.forEach(([key, colour, unit], i) => {
      const values = this.points.map((p) => p[i + 1]).filter((v) => v !== null);
      if (values.length < 2) return;
      const lo = Math.min(...values), hi = Math.max(...values);
      const span = hi - lo || 1;
      g.strokeStyle = colour;
      g.lineWidth = 1.5;
      g.beginPath();
      let started = false;
      for (const p of this.points) {
        if (p[i + 1] === null) continue;
        const x = c.width * (1 - (now - p[0]) / TREND_S);
        const y = c.height - 2 - (c.height - 4) * ((p[i + 1] - lo) / span);
        if (started) g.lineTo(x, y); else g.moveTo(x, y);
        started = true;
      }
      g.stroke();
      titles.push(`${key.split('_')[0]} ${lo.toFixed(2)}–${hi.toFixed(2)} ${unit}`);
    });
    c.dataset.points = String(this.points.length);
    c.title = titles.join(', ');
  }
}

export class DeviceTable {
  constructor(table) {
    this.body = table.tBodies[0];
    this.rows = new Map();
  }

  // `faults` (the run's log) gives a last fault that comes as bare text its time.
  update(devices, faults) {
    if (!Array.isArray(devices)) return;
    const times = new Map();
    if (Array.isArray(faults)) {
      for (const f of faults) if (f && typeof f.text === 'string' && isNum(f.t_s)) times.set(f.text, f.t_s);
    }
    for (const d of devices) {
      if (!d) continue;
      const key = `${d.bus}:${d.id}`;
      let r = this.rows.get(key);
      if (!r) {
        const cells = {};
        const health = el('span', { class: 'health' });
        cells.health = health;
        const tds = [el('td', { text: String(d.bus ?? '') }), el('td', { text: String(d.id ?? '') }),
          el('td', { class: 'joint', text: String(d.joint ?? '') }), el('td', {}, health)];
        for (const c of COUNTERS) {
          cells[c] = el('td', { 'data-field': c, text: '–' });
          tds.push(cells[c]);
        }
        for (const [c] of HEALTH) {
          cells[c] = el('td', { 'data-field': c, text: 'n/a' });
          tds.push(cells[c]);
        }
        const trend = new Trend();
        tds.push(el('td', { 'data-field': 'trend' }, trend.canvas));
        cells.fault = el('td', { class: 'fault', 'data-field': 'last_fault' });
        tds.push(cells.fault);
        const row = el('tr', { 'data-device': key }, ...tds);
        this.body.append(row);
        r = { row, cells, trend };
        this.rows.set(key, r);
      }
      const latest = typeof d.health === 'string' ? d.health : 'unknown';
      const health = d.faulted ? 'faulted' : latest;
      r.row.dataset.health = health;
      r.cells.health.dataset.health = health;
      r.cells.health.title = `latest transaction: ${latest.replace('_', ' ')}`;
      const label = health.replace('_', ' ');
      if (r.cells.health.textContent !== label) r.cells.health.textContent = label;
      for (const c of COUNTERS) {
        const text = fmtInt(d[c]);
        if (r.cells[c].textContent !== text) r.cells[c].textContent = text;
        r.cells[c].classList.toggle('nonzero', c !== 'transactions' && isNum(d[c]) && d[c] > 0);
      }
      for (const [c, show] of HEALTH) {
        const text = isNum(d[c]) ? show(d[c]) : 'n/a';
        if (r.cells[c].textContent !== text) r.cells[c].textContent = text;
        r.cells[c].classList.toggle('nonzero', c === 'error_bits' && isNum(d[c]) && d[c] > 0);
      }
      r.trend.add(d);
      let fault = typeof d.last_fault === 'string' && times.has(d.last_fault)
        ? faultText({ t_s: times.get(d.last_fault), text: d.last_fault })
        : faultText(d.last_fault);
      // The row already names the device: "legs id 3 (lf_ankle): timeout" -> "timeout".
      const own = fault.indexOf(`${d.bus} id ${d.id} `);
      if (own >= 0) {
        const colon = fault.indexOf(': ', own);
        if (colon > own) fault = fault.slice(0, own) + fault.slice(colon + 2);
      }
      if (r.cells.fault.textContent !== fault) {
        r.cells.fault.textContent = fault;
        r.cells.fault.title = fault;
      }
    }
  }
}

export function showFaults(faults) {
  if (!Array.isArray(faults)) return;
  const list = document.getElementById('fault-log');
  if (list.dataset.count === String(faults.length)) return;
  list.dataset.count = String(faults.length);
  list.replaceChildren();
  if (faults.length === 0) {
    list.append(el('li', { class: 'empty', text: 'no faults' }));
    return;
  }
  for (const f of faults) list.append(el('li', { class: 'fault', text: faultText(f) }));
  list.scrollTop = list.scrollHeight;
}
