// Chart.js line charts of one joint's last seconds (commanded, measured,
// limits; velocity) and the loop's jitter histogram. Chart.js comes from
// Debian's UMD build as window.Chart.

import { isNum, jointUnit } from './format.js';

const WINDOW_S = 10;
const COLORS = { cmd: '#5fb3f9', meas: '#f2a35e', vel: '#b58cf5', limit: '#ef5b5b', grid: '#2a3039', tick: '#8d96a3' };

function chartLib() {
  return window.Chart || null;
}

function lineOptions(yTitle) {
  return {
    animation: false,
    responsive: true,
    maintainAspectRatio: false,
    parsing: false,
    normalized: true,
    interaction: { mode: 'nearest', intersect: false },
    plugins: { legend: { labels: { color: COLORS.tick, boxWidth: 12 } }, tooltip: { enabled: false } },
    elements: { point: { radius: 0 }, line: { borderWidth: 1.5 } },
    scales: {
      x: { type: 'linear', ticks: { color: COLORS.tick, maxTicksLimit: 6 }, grid: { color: COLORS.grid },
           title: { display: true, text: 'run time (s)', color: COLORS.tick } },
      y: { ticks: { color: COLORS.tick }, grid: { color: COLORS.grid },
           title: { display: true, text: yTitle, color: COLORS.tick } },
    },
  };
}

// Per-joint history of the last WINDOW_S seconds, kept for every joint so
// that selecting another one shows its past at once.
export class JointHistory {
  constructor() {
    this.series = new Map();
  }

  add(t, joints) {
    if (!isNum(t) || !Array.isArray(joints)) return;
    // Time went back (a replay looped or was sought): a new history.
    if (isNum(this.lastT) && t < this.lastT) this.series.clear();
    this.lastT = t;
    for (const j of joints) {
      if (!j || typeof j.name !== 'string') continue;
      let s = this.series.get(j.name);
      if (!s) {
        s = { cmd: [], meas: [], vel: [] };
        this.series.set(j.name, s);
      }
      if (isNum(j.cmd)) s.cmd.push({ x: t, y: j.cmd });
      if (isNum(j.meas)) s.meas.push({ x: t, y: j.meas });
      if (isNum(j.vel)) s.vel.push({ x: t, y: j.vel });
      for (const k of ['cmd', 'meas', 'vel']) {
        const a = s[k];
        let drop = 0;
        while (drop < a.length && a[drop].x < t - WINDOW_S) drop++;
        if (drop) a.splice(0, drop);
      }
    }
  }

  get(name) {
    return this.series.get(name) || { cmd: [], meas: [], vel: [] };
  }
}

export class JointCharts {
  constructor(positionCanvas, velocityCanvas) {
    const Chart = chartLib();
    this.available = !!Chart;
    if (!Chart) return;
    this.position = new Chart(positionCanvas, {
      type: 'line',
      data: {
        datasets: [
          { label: 'commanded', data: [], borderColor: COLORS.cmd },
          { label: 'measured', data: [], borderColor: COLORS.meas },
          { label: 'limits', data: [], borderColor: COLORS.limit, borderDash: [5, 4], borderWidth: 1, spanGaps: false },
        ],
      },
      options: lineOptions('position'),
    });
    this.velocity = new Chart(velocityCanvas, {
      type: 'line',
      data: { datasets: [{ label: 'commanded velocity', data: [], borderColor: COLORS.vel }] },
      options: lineOptions('velocity'),
    });
  }

  // Redraws the selected joint; values scaled to the joint's display unit.
  draw(joint, series, t) {
    if (!this.available || !joint || !isNum(t)) return;
    const u = jointUnit(joint);
    const scale = (a) => a.map((p) => ({ x: p.x, y: p.y * u.scale }));
    // The first seconds fill the window from its left edge.
    const x0 = Math.max(t - WINDOW_S, 0);
    t = Math.max(t, WINDOW_S);
    const pos = this.position;
    pos.data.datasets[0].data = scale(series.cmd);
    pos.data.datasets[1].data = scale(series.meas);
    // Both limits in one dataset, a gap (NaN) between them.
    const lim = [];
    if (isNum(joint.min)) lim.push({ x: x0, y: joint.min * u.scale }, { x: t, y: joint.min * u.scale });
    if (lim.length) lim.push({ x: t, y: NaN });
    if (isNum(joint.max)) lim.push({ x: x0, y: joint.max * u.scale }, { x: t, y: joint.max * u.scale });
    pos.data.datasets[2].data = lim;
    pos.options.scales.x.min = x0;
    pos.options.scales.x.max = t;
    pos.options.scales.y.title.text = `position (${u.pos})`;
    pos.update('none');

    const vel = this.velocity;
    vel.data.datasets[0].data = scale(series.vel);
    vel.options.scales.x.min = x0;
    vel.options.scales.x.max = t;
    vel.options.scales.y.title.text = `velocity (${u.vel})`;
    vel.update('none');
  }
}

export class JitterHistogram {
  constructor(canvas) {
    const Chart = chartLib();
    this.available = !!Chart;
    if (!Chart) return;
    this.chart = new Chart(canvas, {
      type: 'bar',
      data: { labels: [], datasets: [{ label: 'cycles', data: [], backgroundColor: '#5fb3f9' }] },
      options: {
        animation: false,
        responsive: true,
        maintainAspectRatio: false,
        plugins: { legend: { display: false }, tooltip: { enabled: false } },
        scales: {
          x: { ticks: { color: COLORS.tick, maxRotation: 0, autoSkip: true, maxTicksLimit: 8 }, grid: { display: false },
               title: { display: true, text: 'jitter (ms)', color: COLORS.tick } },
          // Counts span decades: a log scale labelled at the powers of ten.
          y: { type: 'logarithmic', min: 0.7, grid: { color: COLORS.grid },
               ticks: { color: COLORS.tick,
                        callback: (v) => (v >= 1 && Number.isInteger(Math.log10(v)) ? String(v) : '') } },
        },
      },
    });
  }

  draw(hist) {
    if (!this.available || !hist || !Array.isArray(hist.counts) || !Array.isArray(hist.edges_ms)) return;
    const edges = hist.edges_ms;
    this.chart.data.labels = hist.counts.map((_, i) => (isNum(edges[i]) ? edges[i].toFixed(2) : '') +
      (i === hist.counts.length - 1 && edges.length <= hist.counts.length ? '+' : ''));
    // A log scale cannot show 0: empty bins stay empty.
    this.chart.data.datasets[0].data = hist.counts.map((c) => (isNum(c) && c > 0 ? c : null));
    this.chart.update('none');
  }
}
