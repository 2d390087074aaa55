// The IMU panel: per IMU its attitude, angular rates, the age of its
// reading, the cycle's late and missing counts, and roll and pitch over the
// last seconds against the tilt watch's limit (when the robot file sets one).

import { el, fmt, fmtInt, isNum } from './format.js';

const TREND_S = 10;
const LINES = [['roll_deg', '#ff7a7a'], ['pitch_deg', '#7ab4ff']];
const FIELDS = ['roll_deg', 'pitch_deg', 'yaw_deg', 'rates', 'age', 'late_cycles', 'missing_reports'];

// Roll (red) and pitch (blue) in one small canvas, on a symmetric scale that
// holds the tilt limit (dashed) when there is one.
class AttitudeTrend {
  constructor(limitDeg) {
    this.limit = isNum(limitDeg) ? limitDeg : null;
    this.canvas = el('canvas', { class: 'spark', width: 140, height: 36 });
    this.points = [];  // [seconds, roll, pitch]
  }

  add(imu) {
    if (!isNum(imu.roll_deg) || !isNum(imu.pitch_deg)) return;
    const t = performance.now() / 1000;
    this.points.push([t, imu.roll_deg, imu.pitch_deg]);
    while (this.points.length && this.points[0][0] < t - TREND_S) this.points.shift();
    this.draw(t);
  }

  draw(now) {
    const c = this.canvas;
    const g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    let span = this.limit ?? 5;
    for (const p of this.points) span = Math.max(span, Math.abs(p[1]), Math.abs(p[2]));
    const y = (v) => c.height / 2 - (c.height / 2 - 2) * (v / span);
    g.strokeStyle = '#3a4250';
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(0, y(0));
    g.lineTo(c.width, y(0));
    g.stroke();
    if (this.limit !== null) {
      g.setLineDash([3, 3]);
      g.strokeStyle = '#e0b050';
      g.beginPath();
      for (const v of [this.limit, -this.limit]) {
        g.moveTo(0, y(v));
        g.lineTo(c.width, y(v));
      }
      g.stroke();
      g.setLineDash([]);
    }
    LINES.forEach(([, colour], i) => {
      g.strokeStyle = colour;
      g.lineWidth = 1.5;
      g.beginPath();
      this.points.forEach((p, k) => {
        const x = c.width * (1 - (now - p[0]) / TREND_S);
        if (k) g.lineTo(x, y(p[i + 1])); else g.moveTo(x, y(p[i + 1]));
      });
      g.stroke();
    });
    c.dataset.points = String(this.points.length);
    c.title = `roll (red) and pitch (blue), ±${span.toFixed(1)}°` +
      (this.limit !== null ? `; tilt limit ${this.limit.toFixed(1)}° (dashed)` : '');
  }
}

export class ImuPanel {
  // `info` from /api/info: its IMUs and the tilt watch's limit. The panel
  // stays hidden for a robot without IMUs.
  constructor(section, info) {
    this.section = section;
    this.body = section.querySelector('tbody');
    this.rows = new Map();
    const imus = Array.isArray(info.imus) ? info.imus : [];
    this.limit = isNum(info.tilt_limit_deg) ? info.tilt_limit_deg : null;
    const note = section.querySelector('.tilt-limit');
    note.textContent = this.limit !== null ? `tilt watch at ${this.limit.toFixed(1)}°` : 'no tilt watch';
    section.hidden = imus.length === 0;
  }

  row(imu) {
    let r = this.rows.get(imu.name);
    if (r) return r;
    const cells = { health: el('span', { class: 'health' }) };
    const tds = [el('td', { class: 'name', text: String(imu.name) }), el('td', {}, cells.health)];
    for (const f of FIELDS) {
      cells[f] = el('td', { 'data-field': f, text: '–' });
      tds.push(cells[f]);
    }
    const trend = new AttitudeTrend(this.limit);
    tds.push(el('td', { 'data-field': 'trend' }, trend.canvas));
    const tr = el('tr', { 'data-imu': imu.name }, ...tds);
    this.body.append(tr);
    r = { tr, cells, trend };
    this.rows.set(imu.name, r);
    return r;
  }

  update(imus) {
    if (!Array.isArray(imus)) return;
    for (const imu of imus) {
      if (!imu || typeof imu.name !== 'string') continue;
      const r = this.row(imu);
      const health = typeof imu.health === 'string' ? imu.health : 'unknown';
      r.tr.dataset.health = health;
      r.cells.health.dataset.health = health;
      if (r.cells.health.textContent !== health) r.cells.health.textContent = health;
      const rates = Array.isArray(imu.rate_dps) && imu.rate_dps.every(isNum)
        ? imu.rate_dps.map((v) => v.toFixed(1)).join(' / ') + ' °/s' : '–';
      const text = {
        roll_deg: fmt(imu.roll_deg, 1, '°'),
        pitch_deg: fmt(imu.pitch_deg, 1, '°'),
        yaw_deg: fmt(imu.yaw_deg, 1, '°'),
        rates,
        age: isNum(imu.age_s) ? `${(imu.age_s * 1e3).toFixed(0)} ms` : '–',
        late_cycles: fmtInt(imu.late_cycles),
        missing_reports: fmtInt(imu.missing_reports),
      };
      for (const f of FIELDS) {
        if (r.cells[f].textContent !== text[f]) r.cells[f].textContent = text[f];
        if (isNum(imu[f])) r.cells[f].dataset.value = String(imu[f]);
      }
      for (const f of ['late_cycles', 'missing_reports']) {
        r.cells[f].classList.toggle('nonzero', isNum(imu[f]) && imu[f] > 0);
      }
      for (const f of ['roll_deg', 'pitch_deg']) {  // beyond the tilt watch's limit
        r.cells[f].classList.toggle('nonzero', this.limit !== null && isNum(imu[f]) && Math.abs(imu[f]) > this.limit);
      }
      r.trend.add(imu);
    }
  }
}
