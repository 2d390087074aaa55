// The dashboard page: one GET /api/info, then every state from /api/stream.

import { getInfo, openStream } from './api.js';
import { JitterHistogram, JointCharts, JointHistory } from './charts.js';
import { makeControls } from './controls.js';
import { startEvolve } from './evolve.js';
import { startHerd } from './herd.js';
import { ImuPanel } from './imu.js';
import { DeviceTable, JointList, showFaults, showInfo, showLoop, showMotion, showPhase } from './panels.js';
import { FigureView } from './view3d.js';

const CHART_INTERVAL_MS = 100;
const HIST_INTERVAL_MS = 500;

function showPageError(text) {
  const banner = document.getElementById('page-error');
  banner.textContent = text;
  banner.hidden = false;
}

function setStreamStatus(status, text) {
  const s = document.getElementById('stream-status');
  s.dataset.status = status;
  s.textContent = text;
  document.body.dataset.stream = status;
}

async function start() {
  let info;
  try {
    info = await getInfo();
  } catch (e) {
    showPageError(`Cannot read the run: ${e.message}`);
    setStreamStatus('ended', 'no run');
    return;
  }
  if (info.kind === 'herd') {
    await startHerd(info, setStreamStatus);
    return;
  }
  if (info.kind === 'evolve') {
    await startEvolve(info, setStreamStatus, showPageError);
    return;
  }
  showInfo(info);
  const joints = Array.isArray(info.joints) ? info.joints : [];
  const jointsByName = new Map(joints.map((j) => [j.name, j]));

  let figure = null;
  try {
    figure = new FigureView(document.getElementById('view3d'), document.getElementById('view3d-note'));
    figure.setModel(info.model);
  } catch (e) {
    // The 3-D view is an extra: the rest of the page works without it.
    const note = document.getElementById('view3d-note');
    note.textContent = `3-D view unavailable: ${e.message}`;
    note.hidden = false;
    figure = null;
  }

  const history = new JointHistory();
  const charts = new JointCharts(document.getElementById('chart-position'), document.getElementById('chart-velocity'));
  const jitter = new JitterHistogram(document.getElementById('chart-jitter'));
  if (!charts.available) showPageError('Chart.js did not load (/lib/chart.umd.js): no charts.');
  const devices = new DeviceTable(document.getElementById('device-table'));
  const imus = new ImuPanel(document.getElementById('panel-imus'), info);
  const controls = makeControls(info);

  let last = null;
  let lastChart = 0;
  let lastHist = 0;
  const drawCharts = () => {
    if (!last || !list.selected) return;
    charts.draw(jointsByName.get(list.selected), history.get(list.selected), last.t_s);
  };
  const list = new JointList(document.getElementById('joint-list'), joints, drawCharts);
  if (joints.length) list.select(joints[0].name);
  document.body.dataset.ready = '1';

  openStream({
    onOpen: () => setStreamStatus('live', 'live'),
    onState: (state) => {
      if (!state || typeof state !== 'object') return;
      last = state;
      setStreamStatus('live', 'live');
      showPhase(state);
      showMotion(info, state);
      list.update(state.joints);
      history.add(state.t_s, state.joints);
      showLoop(state.loop);
      devices.update(state.devices, state.faults);
      imus.update(state.imus);
      showFaults(state.faults);
      controls.refresh(state);
      if (figure) figure.update(state.bodies);
      const now = performance.now();
      if (now - lastChart >= CHART_INTERVAL_MS) {
        lastChart = now;
        drawCharts();
      }
      if (now - lastHist >= HIST_INTERVAL_MS && state.loop) {
        lastHist = now;
        jitter.draw(state.loop.jitter_hist);
      }
    },
    onEnd: () => {
      // The run is over (or its server gone): keep the last values on screen.
      setStreamStatus('ended', 'run ended');
      controls.end();
      drawCharts();
      if (last && last.loop) jitter.draw(last.loop.jitter_hist);
    },
  });
}

start().catch((e) => {
  showPageError(`Dashboard error: ${e.message}`);
  console.error(e);
});
