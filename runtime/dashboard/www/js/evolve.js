// An evolve run (`animrt evolve --dashboard`): fitness curves per
// generation, invalid and fallen individuals, and the best gait so far
// playing on the figure. The generations come from /api/history once, then
// from each state's `last` (or /api/history?from=N when some were missed).

import { openStream, post, token } from './api.js';
import { fmt, isNum, setText } from './format.js';
import { FigureView } from './view3d.js';

const COLORS = { best: '#46c277', average: '#5fb3f9', fell: '#ef5b5b', invalid: '#e6b341', grid: '#2a3039', tick: '#8d96a3' };
const PHASES = { running: 'evolving', stopping: 'stopping', ended: 'ended' };

function positive(x) {
  return isNum(x) && x > 0 ? x : null;
}

class Curves {
  constructor(fitnessCanvas, fallsCanvas) {
    const Chart = window.Chart || null;
    this.fitnessCanvas = fitnessCanvas;
    this.available = !!Chart;
    this.generations = [];
    if (!Chart) return;
    const axes = (yType, yTitle) => ({
      x: { type: 'linear', ticks: { color: COLORS.tick, precision: 0, maxTicksLimit: 10 }, grid: { color: COLORS.grid },
           title: { display: true, text: 'generation', color: COLORS.tick } },
      y: { type: yType, ticks: { color: COLORS.tick }, grid: { color: COLORS.grid },
           title: { display: true, text: yTitle, color: COLORS.tick } },
    });
    const common = {
      animation: false,
      responsive: true,
      maintainAspectRatio: false,
      parsing: false,
      normalized: true,
      plugins: { legend: { labels: { color: COLORS.tick, boxWidth: 12 } }, tooltip: { enabled: false } },
    };
    this.fitness = new Chart(fitnessCanvas, {
      type: 'line',
      data: {
        datasets: [
          { label: 'best', data: [], borderColor: COLORS.best, backgroundColor: COLORS.best, pointRadius: 2 },
          { label: 'average', data: [], borderColor: COLORS.average, backgroundColor: COLORS.average, pointRadius: 2 },
        ],
      },
      options: { ...common, elements: { line: { borderWidth: 1.5 } }, scales: axes('logarithmic', 'fitness') },
    });
    this.falls = new Chart(fallsCanvas, {
      type: 'bar',
      data: {
        datasets: [
          { label: 'fell', data: [], backgroundColor: COLORS.fell },
          { label: 'invalid', data: [], backgroundColor: COLORS.invalid },
        ],
      },
      options: { ...common, scales: {
        x: { ...axes('linear', '').x, offset: true },
        y: { ...axes('linear', 'individuals').y, min: 0, suggestedMax: 1, ticks: { color: COLORS.tick, precision: 0 } },
      } },
    });
  }

  // Appends generations (in order; a repeated or out-of-order one is ignored).
  add(list) {
    let added = false;
    for (const g of list || []) {
      if (!g || g.generation !== this.generations.length) continue;
      this.generations.push(g);
      added = true;
    }
    if (added) this.draw();
    return added;
  }

  draw() {
    this.fitnessCanvas.dataset.points = String(this.generations.length);
    if (!this.available) return;
    const gens = this.generations;
    this.fitness.data.datasets[0].data = gens.map((g) => ({ x: g.generation, y: positive(g.best) }));
    this.fitness.data.datasets[1].data = gens.map((g) => ({ x: g.generation, y: positive(g.average) }));
    this.fitness.update('none');
    this.falls.data.datasets[0].data = gens.map((g) => ({ x: g.generation, y: isNum(g.fell) ? g.fell : 0 }));
    this.falls.data.datasets[1].data = gens.map((g) => ({ x: g.generation, y: isNum(g.invalid) ? g.invalid : 0 }));
    this.falls.update('none');
  }
}

async function history(from) {
  const res = await fetch(`/api/history?from=${from}`, { cache: 'no-store' });
  if (!res.ok) throw new Error(`GET /api/history: ${res.status} ${res.statusText}`);
  const body = await res.json();
  return body && body.from === from && Array.isArray(body.generations) ? body.generations : [];
}

function showBest(best, playback) {
  document.getElementById('evolve-best').dataset.generation = best && isNum(best.generation) ? String(best.generation) : '';
  setText('best-generation', best && isNum(best.generation) ? String(best.generation) : '–');
  setText('best-fitness', best ? fmt(best.fitness, 2) + (best.fell ? ' (falls)' : '') : '–');
  setText('best-speed', best ? fmt(best.speed_mps, 3, ' m/s') : '–');
  setText('best-stride', best ? fmt(best.stride_m, 3, ' m') : '–');
  setText('best-duty', best ? fmt(best.duty_factor, 2) : '–');
  setText('best-energy', best ? fmt(best.energy_j, 2, ' J/cycle') : '–');
  setText('best-playback', playback && isNum(playback.t_s) && isNum(playback.period_s)
    ? `${playback.t_s.toFixed(2)} s of a ${playback.period_s.toFixed(2)} s stride` : '–');
  setText('best-phenotype', best && typeof best.phenotype === 'string' ? best.phenotype : '');
}

export async function startEvolve(info, setStreamStatus, showPageError) {
  document.querySelector('main').hidden = true;
  document.getElementById('panel-evolve').hidden = false;
  setText('robot-name', `evolve ${info.name || ''}`);
  const parts = [];
  if (isNum(info.population)) parts.push(`population ${info.population}`);
  if (isNum(info.workers)) parts.push(`${info.workers} worker${info.workers === 1 ? '' : 's'}`);
  if (isNum(info.seed)) parts.push(`seed ${info.seed}`);
  setText('robot-backend', parts.join(' · '));
  setText('motion-source', 'grammatical evolution');
  setText('evolve-run', [info.grammar, info.model_file].filter(Boolean).map((p) => p.split('/').pop()).join(' · '));
  document.title = `evolve ${info.name || ''} · animrt dashboard`;
  const total = isNum(info.generations) ? info.generations : null;

  const curves = new Curves(document.getElementById('chart-fitness'), document.getElementById('chart-falls'));
  if (!curves.available) showPageError('Chart.js did not load (/lib/chart.umd.js): no charts.');
  let figure = null;
  const note = document.getElementById('evolve-view3d-note');
  try {
    figure = new FigureView(document.getElementById('evolve-view3d'), note);
    figure.setModel(info.model);
  } catch (e) {
    note.textContent = `3-D view unavailable: ${e.message}`;
    note.hidden = false;
    figure = null;
  }

  const stop = document.getElementById('btn-evolve-stop');
  const error = document.getElementById('evolve-error');
  document.getElementById('evolve-readonly').hidden = token !== '';
  let ended = false;
  let phase = 'running';
  const refreshStop = () => {
    stop.disabled = token === '' || ended || phase !== 'running';
  };
  refreshStop();
  stop.addEventListener('click', async () => {
    const r = await post('/api/stop', {});
    error.hidden = r.ok;
    error.textContent = r.ok ? '' : r.error;
  });

  curves.add(await history(0));
  curves.draw();
  let fetching = false;
  const catchUp = async (completed) => {
    if (fetching || completed <= curves.generations.length) return;
    fetching = true;
    try {
      curves.add(await history(curves.generations.length));
    } catch (e) {
      if (!ended) showPageError(`Cannot read the generations: ${e.message}`);
    } finally {
      fetching = false;
    }
  };

  document.body.dataset.ready = '1';
  openStream({
    onOpen: () => setStreamStatus('live', 'live'),
    onState: (state) => {
      if (!state || typeof state !== 'object') return;
      setStreamStatus('live', 'live');
      phase = typeof state.phase === 'string' ? state.phase : phase;
      const p = document.getElementById('phase');
      p.dataset.phase = phase === 'ended' ? 'ended' : phase === 'stopping' ? 'stop_ramp' : 'motion';
      setText('phase', PHASES[phase] || phase);
      setText('run-time', fmt(state.t_s, 1, ' s'));
      const gen = isNum(state.generation) ? state.generation : null;
      const shown = document.getElementById('evolve-generation');
      shown.dataset.generation = gen === null ? '' : String(gen);
      setText('evolve-generation', `${gen === null ? '–' : gen} / ${total === null ? '?' : total}`);
      setText('evolve-evaluating', isNum(state.evaluating)
        ? `evaluating generation ${state.evaluating} (${fmt(state.generation_elapsed_s, 0, ' s')})`
        : state.stopped ? 'stopped from the dashboard' : '');
      // The newest generation comes with the state; a gap is fetched.
      if (state.last && state.last.generation === curves.generations.length) curves.add([state.last]);
      if (isNum(state.completed) && state.completed > curves.generations.length && phase !== 'ended') {
        catchUp(state.completed);
      }
      showBest(state.best, state.playback);
      if (figure && state.bodies) figure.update(state.bodies);
      refreshStop();
    },
    onEnd: () => {
      ended = true;
      setStreamStatus('ended', 'run ended');
      refreshStop();
    },
  });
}
