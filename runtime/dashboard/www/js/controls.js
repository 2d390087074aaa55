// Controls: stop, manual mode with a slider per joint, steering, a show's
// play, pause and seek. Every control needs the run's token; without it
// they are shown disabled.

import { post, throttle, token } from './api.js';
import { el, isNum, jointUnit } from './format.js';

const JOG_INTERVAL_MS = 50;
const STEER_INTERVAL_MS = 100;
const SHOW_SEEK_INTERVAL_MS = 100;

// A replay of a recording: play, pause and seek (no token needed: it
// moves no robot).
class ReplayControls {
  constructor(info, error) {
    const range = Array.isArray(info.replay_range_s) ? info.replay_range_s : [];
    const [lo, hi] = isNum(range[0]) && isNum(range[1]) ? range : [0, 1];
    this.error = error;
    this.playing = true;
    this.seek = document.getElementById('seek');
    this.play = document.getElementById('btn-play');
    this.value = document.getElementById('seek-value');
    this.seek.min = String(lo);
    this.seek.max = String(hi);
    this.seek.value = String(lo);
    document.getElementById('replay').hidden = false;
    document.getElementById('live-controls').hidden = true;
    const send = throttle((t, playing) => this.send(t, playing), 100);
    this.seek.addEventListener('input', () => {
      this.dragging = true;
      this.show(Number(this.seek.value));
      send(Number(this.seek.value), false);
    });
    this.seek.addEventListener('change', () => {
      this.dragging = false;
      send(Number(this.seek.value), this.playing);
    });
    this.play.addEventListener('click', () => {
      this.playing = !this.playing;
      this.play.textContent = this.playing ? 'Pause' : 'Play';
      send(Number(this.seek.value), this.playing);
    });
  }

  async send(t_s, playing) {
    const res = await post('/api/seek', { t_s, playing });
    this.error.hidden = res.ok;
    this.error.textContent = res.ok ? '' : res.error;
  }

  show(t) {
    this.value.textContent = isNum(t) ? `${t.toFixed(1)} s` : '–';
  }

  refresh(state) {
    if (!state || this.dragging || !isNum(state.t_s)) return;
    this.seek.value = String(state.t_s);
    this.show(state.t_s);
  }

  end() {
    this.seek.disabled = true;
    this.play.disabled = true;
  }
}

export function makeControls(info) {
  return info && info.replay
    ? new ReplayControls(info, document.getElementById('control-error'))
    : new Controls(info);
}

export class Controls {
  constructor(info) {
    this.info = info;
    this.enabled = token !== '';
    this.ended = false;
    this.stop = document.getElementById('btn-stop');
    this.manual = document.getElementById('manual-toggle');
    this.resume = document.getElementById('btn-resume');
    this.jogBox = document.getElementById('jog-sliders');
    this.error = document.getElementById('control-error');
    this.sliders = new Map();

    document.getElementById('readonly-note').hidden = this.enabled;

    this.stop.addEventListener('click', () => this.send('/api/stop', {}));
    this.manual.addEventListener('change', () => this.send('/api/manual', { on: this.manual.checked }));
    this.resume.addEventListener('click', () => this.send('/api/manual', { on: false }));

    this.buildJog(Array.isArray(info.joints) ? info.joints : []);
    this.buildSteer(info.motion || {});
    this.buildShow(info.motion || {});
    this.refresh(null);
  }

  // A show: play/pause and a seek bar over its length (from the state).
  buildShow(motion) {
    if (!motion.show) return;
    document.getElementById('show').hidden = false;
    const play = document.getElementById('btn-show-play');
    const seek = document.getElementById('show-seek');
    const position = document.getElementById('show-position');
    this.showInputs = { play, seek, position, playing: true };
    const send = throttle((t_s) => this.send('/api/show', { action: 'seek', t_s }), SHOW_SEEK_INTERVAL_MS);
    seek.addEventListener('input', () => {
      this.showDragging = true;
      position.textContent = `${Number(seek.value).toFixed(1)} s`;
      send(Number(seek.value));
    });
    seek.addEventListener('change', () => {
      this.showDragging = false;
      this.send('/api/show', { action: 'seek', t_s: Number(seek.value) });
    });
    play.addEventListener('click', () => {
      this.send('/api/show', { action: this.showInputs.playing ? 'pause' : 'play' });
    });
  }

  refreshShow(state, can, phase) {
    const s = this.showInputs;
    if (!s) return;
    s.play.disabled = !can || phase !== 'motion';
    s.seek.disabled = !can || phase !== 'motion';
    const m = state && state.motion;
    if (!m) return;
    if (isNum(m.duration_s)) s.seek.max = String(m.duration_s);
    s.playing = !!m.playing || phase !== 'motion';
    s.play.textContent = s.playing ? 'Pause' : 'Play';
    if (!this.showDragging && isNum(m.position_s)) {
      s.seek.value = String(m.position_s);
      s.position.textContent = `${m.position_s.toFixed(1)} s`;
    }
  }

  buildJog(joints) {
    for (const j of joints) {
      if (!j || typeof j.name !== 'string' || !isNum(j.min) || !isNum(j.max)) continue;
      const u = jointUnit(j);
      const input = el('input', { type: 'range', min: String(j.min), max: String(j.max), step: String((j.max - j.min) / 500) });
      input.dataset.joint = j.name;
      const out = el('output', { class: 'num' });
      const show = () => { out.textContent = (Number(input.value) * u.scale).toFixed(1) + u.pos; };
      const jog = throttle((position) => this.send('/api/jog', { joint: j.name, position }), JOG_INTERVAL_MS);
      input.addEventListener('input', () => {
        this.dragging = j.name;
        show();
        jog(Number(input.value));
      });
      input.addEventListener('change', () => { this.dragging = null; });
      this.jogBox.append(el('label', {}, j.name, input, out));
      this.sliders.set(j.name, { input, show });
    }
  }

  buildSteer(motion) {
    if (!motion.steerable) return;
    document.getElementById('steer').hidden = false;
    const speed = document.getElementById('steer-speed');
    const turn = document.getElementById('steer-turn');
    const range = (input, r, fallback, start) => {
      const [lo, hi] = Array.isArray(r) && isNum(r[0]) && isNum(r[1]) ? r : fallback;
      input.step = 'any';
      input.min = String(lo);
      input.max = String(hi);
      input.value = String(Math.min(hi, Math.max(lo, start(lo, hi))));
    };
    // Until the first command the gait runs at its own speed, which the
    // state does not report: the outputs say so with a dash.
    range(speed, motion.speed_mps, [0, 0.3], (lo, hi) => (lo + hi) / 2);
    range(turn, motion.turn_rps, [-1, 1], () => 0);
    this.steerKnown = false;
    this.steerInputs = { speed, turn };
    const steer = throttle(() => this.send('/api/steer', {
      speed_mps: Number(speed.value), turn_rps: Number(turn.value),
    }), STEER_INTERVAL_MS);
    for (const input of [speed, turn]) {
      input.addEventListener('input', () => {
        this.steering = true;
        this.steerKnown = true;
        this.showSteer();
        steer();
      });
      input.addEventListener('change', () => { this.steering = false; });
    }
    this.showSteer();
  }

  showSteer() {
    if (!this.steerInputs) return;
    const show = (id, input, unit) => {
      document.getElementById(id).textContent = this.steerKnown ? `${Number(input.value).toFixed(2)} ${unit}` : '–';
    };
    show('steer-speed-value', this.steerInputs.speed, 'm/s');
    show('steer-turn-value', this.steerInputs.turn, 'rad/s');
  }

  async send(path, body) {
    if (!this.enabled || this.ended) return;
    const res = await post(path, body);
    if (res.ok) {
      this.error.hidden = true;
      this.error.textContent = '';
    } else {
      this.error.textContent = res.error;
      this.error.hidden = false;
    }
  }

  // Follows the run: manual mode's switch and sliders, the steer command,
  // and what may be used in the current phase.
  refresh(state) {
    const manualOn = !!(state && state.manual && state.manual.on);
    const phase = state && state.phase;
    const live = phase === 'motion' || phase === 'start_ramp';
    const can = this.enabled && !this.ended;
    this.stop.disabled = !can || phase === 'stop_ramp' || phase === 'ended';
    this.manual.disabled = !can || !live;
    this.manual.checked = manualOn;
    this.resume.disabled = !can || !manualOn;
    this.jogBox.hidden = !manualOn;
    for (const [name, s] of this.sliders) {
      s.input.disabled = !can || !manualOn;
      if (this.dragging === name) continue;
      const held = state && state.manual && state.manual.positions && state.manual.positions[name];
      const joint = state && Array.isArray(state.joints) ? state.joints.find((j) => j && j.name === name) : null;
      const v = isNum(held) ? held : joint && isNum(joint.cmd) ? joint.cmd : null;
      if (v !== null && document.activeElement !== s.input) s.input.value = String(v);
      s.show();
    }
    this.refreshShow(state, can, phase);
    if (this.steerInputs) {
      for (const input of Object.values(this.steerInputs)) input.disabled = !can || !live || manualOn;
      const m = state && state.motion;
      if (m && !this.steering && document.activeElement !== this.steerInputs.speed &&
          document.activeElement !== this.steerInputs.turn) {
        if (isNum(m.speed_mps) && isNum(m.turn_rps)) {
          this.steerInputs.speed.value = String(m.speed_mps);
          this.steerInputs.turn.value = String(m.turn_rps);
          this.steerKnown = true;
        }
        this.showSteer();
      }
    }
  }

  end() {
    this.ended = true;
    this.refresh(null);
  }
}
