// A herd seen from above (`animrt herd --dashboard`): the scene from
// /api/herd once, then every state from /api/stream drawn on a canvas.

import { openStream, post, token } from './api.js';
import { fmt, isNum, setText } from './format.js';

const GROUP_COLOURS = ['#d9534f', '#337ab7', '#5cb85c', '#f0ad4e', '#9b59b6', '#17a2b8', '#e83e8c', '#6c757d'];

function colour(group) {
  return GROUP_COLOURS[((group % GROUP_COLOURS.length) + GROUP_COLOURS.length) % GROUP_COLOURS.length];
}

class HerdView {
  constructor(canvas, scene) {
    this.canvas = canvas;
    this.scene = scene;
    this.state = null;
    const b = Array.isArray(scene.bounds) && scene.bounds.every(isNum) ? scene.bounds : [-10, -10, 10, 10];
    this.bounds = b;
    window.addEventListener('resize', () => this.draw());
  }

  // World (m, y up) to canvas pixels, the bounds fitted with a margin.
  layout() {
    const c = this.canvas;
    const width = c.clientWidth || 800;
    const [xmin, ymin, xmax, ymax] = this.bounds;
    const height = Math.max(200, Math.round(width * (ymax - ymin) / Math.max(1e-9, xmax - xmin)));
    if (c.width !== width || c.height !== height) {
      c.width = width;
      c.height = height;
    }
    const margin = 10;
    const k = Math.min((width - 2 * margin) / (xmax - xmin), (height - 2 * margin) / (ymax - ymin));
    return { k, x: (x) => margin + (x - xmin) * k, y: (y) => height - margin - (y - ymin) * k };
  }

  box(ctx, t, b) {
    if (!b || !Array.isArray(b.center) || !Array.isArray(b.size)) return;
    ctx.save();
    ctx.translate(t.x(b.center[0]), t.y(b.center[1]));
    ctx.rotate(-(b.yaw || 0));
    ctx.fillRect(-b.size[0] * t.k / 2, -b.size[1] * t.k / 2, b.size[0] * t.k, b.size[1] * t.k);
    ctx.restore();
  }

  draw() {
    const ctx = this.canvas.getContext('2d');
    if (!ctx) return;
    const t = this.layout();
    const [xmin, ymin, xmax, ymax] = this.bounds;
    ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
    ctx.fillStyle = '#f4f1e8';
    ctx.fillRect(t.x(xmin), t.y(ymax), (xmax - xmin) * t.k, (ymax - ymin) * t.k);
    ctx.fillStyle = '#555';
    for (const w of this.scene.walls || []) this.box(ctx, t, w);
    const obstacles = (this.state && this.state.obstacles) || [];
    (this.scene.obstacles || []).forEach((o, i) => {
      const down = obstacles[i] && obstacles[i].down;
      ctx.fillStyle = down ? 'rgba(180, 60, 40, 0.85)' : 'rgba(180, 60, 40, 0.2)';
      this.box(ctx, t, o);
    });
    for (const target of this.scene.targets || []) {
      if (!Array.isArray(target.pos)) continue;
      ctx.strokeStyle = colour(target.group);
      ctx.lineWidth = 2;
      const [x, y] = [t.x(target.pos[0]), t.y(target.pos[1])];
      ctx.beginPath();
      ctx.moveTo(x - 6, y - 6); ctx.lineTo(x + 6, y + 6);
      ctx.moveTo(x - 6, y + 6); ctx.lineTo(x + 6, y - 6);
      ctx.stroke();
    }
    const agents = (this.state && this.state.agents) || [];
    const specs = this.scene.agents || [];
    agents.forEach((a, i) => {
      if (!a || !isNum(a.x) || !isNum(a.y)) return;
      const r = Math.max(2, ((specs[i] && specs[i].radius) || 0.25) * t.k);
      const [x, y] = [t.x(a.x), t.y(a.y)];
      ctx.fillStyle = colour(a.group);
      ctx.beginPath();
      ctx.arc(x, y, r, 0, 2 * Math.PI);
      ctx.fill();
      if (isNum(a.heading)) {
        ctx.strokeStyle = '#222';
        ctx.lineWidth = 1;
        ctx.beginPath();
        ctx.moveTo(x, y);
        ctx.lineTo(x + Math.cos(a.heading) * r * 1.8, y - Math.sin(a.heading) * r * 1.8);
        ctx.stroke();
      }
    });
    this.canvas.dataset.agents = String(agents.length);
    // A digest of the agents' positions, for tests: it changes as they walk.
    this.canvas.dataset.digest = agents.reduce((s, a, i) => s + (a && isNum(a.x) && isNum(a.y) ? (i + 1) * (a.x + 2 * a.y) : 0), 0).toFixed(6);
  }

  update(state) {
    this.state = state;
    this.draw();
  }
}

export async function startHerd(info, setStreamStatus) {
  document.querySelector('main').hidden = true;
  const panel = document.getElementById('panel-herd');
  panel.hidden = false;
  setText('robot-name', `herd ${info.scene || ''}`);
  setText('robot-backend', `${info.agents} figures · ${info.speed}× real time`);
  setText('motion-source', 'herd');
  document.title = `herd ${info.scene || ''} · animrt dashboard`;
  const res = await fetch('/api/herd', { cache: 'no-store' });
  if (!res.ok) throw new Error(`GET /api/herd: ${res.status} ${res.statusText}`);
  const scene = await res.json();
  const view = new HerdView(document.getElementById('herd-canvas'), scene);
  const legend = document.getElementById('herd-legend');
  legend.replaceChildren();
  (scene.groups || []).forEach((g, i) => {
    const item = document.createElement('span');
    item.className = 'herd-group';
    item.style.color = colour(i);
    item.textContent = `● ${g.name} (${g.kind}, ${g.count})`;
    legend.append(item);
  });
  const stop = document.getElementById('btn-herd-stop');
  const error = document.getElementById('herd-error');
  stop.disabled = token === '';
  stop.addEventListener('click', async () => {
    const r = await post('/api/stop', {});
    error.hidden = r.ok;
    error.textContent = r.ok ? '' : r.error;
  });
  view.draw();
  document.body.dataset.ready = '1';
  openStream({
    onOpen: () => setStreamStatus('live', 'live'),
    onState: (state) => {
      if (!state || typeof state !== 'object') return;
      setStreamStatus('live', 'live');
      const phase = document.getElementById('phase');
      phase.dataset.phase = state.phase === 'ended' ? 'ended' : 'motion';
      setText('phase', state.phase || '–');
      setText('run-time', fmt(state.t_s, 1, ' s'));
      view.update(state);
    },
    onEnd: () => {
      setStreamStatus('ended', 'run ended');
      stop.disabled = true;
    },
  });
}
