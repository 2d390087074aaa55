// Formatting that never throws: the state may lack optional fields.

export function isNum(x) {
  return typeof x === 'number' && Number.isFinite(x);
}

export function fmt(x, digits = 2, unit = '') {
  return isNum(x) ? x.toFixed(digits) + unit : '–';
}

export function fmtInt(x) {
  return isNum(x) ? String(Math.round(x)) : '–';
}

// A joint's display unit: degrees for a revolute joint, millimetres for a
// prismatic one; the API speaks radians and metres.
export function jointUnit(joint) {
  const prismatic = joint && joint.kind === 'prismatic';
  return {
    scale: prismatic ? 1000 : 180 / Math.PI,
    pos: prismatic ? 'mm' : '°',
    vel: prismatic ? 'mm/s' : '°/s',
  };
}

export function setText(id, text) {
  const el = document.getElementById(id);
  if (el && el.textContent !== text) el.textContent = text;
}

export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') node.className = v;
    else if (k === 'text') node.textContent = v;
    else if (k.startsWith('data-')) node.setAttribute(k, v);
    else node[k] = v;
  }
  for (const c of children) node.append(c);
  return node;
}
