// The run's HTTP API: one GET of /api/info, the state stream, and controls
// that carry the token from the page's URL.

export const token = new URLSearchParams(window.location.search).get('token') || '';

export async function getInfo() {
  const res = await fetch('/api/info', { cache: 'no-store' });
  if (!res.ok) throw new Error(`GET /api/info: ${res.status} ${res.statusText}`);
  return res.json();
}

// POST a control. Resolves to {ok: true} or {ok: false, error: text}; never
// throws, so a refused control is shown, not raised.
export async function post(path, body = {}) {
  try {
    const res = await fetch(path, {
      method: 'POST',
      headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${token}` },
      body: JSON.stringify(body),
    });
    const text = await res.text();
    let json = null;
    try { json = JSON.parse(text); } catch { /* not JSON: keep the text */ }
    if (res.ok && (!json || json.ok !== false)) return { ok: true };
    const why = (json && (json.error || json.message)) || text || res.statusText;
    return { ok: false, error: `${path}: ${res.status} ${why}` };
  } catch (e) {
    return { ok: false, error: `${path}: ${e.message}` };
  }
}

// Opens /api/state's stream. onState gets each parsed state; onEnd is called
// once when the stream closes (the run is over and its server gone). The
// stream is not reopened: a reconnect to a finished run would only log
// network errors.
export function openStream({ onState, onOpen, onEnd }) {
  const source = new EventSource('/api/stream');
  let ended = false;
  const end = (why) => {
    if (ended) return;
    ended = true;
    source.close();
    onEnd(why);
  };
  source.onopen = () => onOpen && onOpen();
  source.onmessage = (ev) => {
    let state;
    try { state = JSON.parse(ev.data); } catch { return; }
    onState(state);
    if (state && state.phase === 'ended') end('ended');
  };
  source.onerror = () => end('closed');
  return { close: () => end('closed') };
}

// At most one call per `ms`, the last one always delivered.
export function throttle(fn, ms) {
  let last = 0;
  let timer = null;
  let pending = null;
  return (...args) => {
    pending = args;
    const wait = last + ms - performance.now();
    if (wait <= 0 && !timer) {
      last = performance.now();
      fn(...pending);
      pending = null;
    } else if (!timer) {
      timer = setTimeout(() => {
        timer = null;
        last = performance.now();
        if (pending) fn(...pending);
        pending = null;
      }, Math.max(wait, 0));
    }
  };
}
