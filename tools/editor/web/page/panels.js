// The page's panels: the list of pairs, the selected pair's values, the validator's problems, and
// the labels over the 3D view (each pair's number at t, each problem at the element it concerns).
const $ = (id) => document.getElementById(id);

export function showPairs(state, selected, onSelect) {
  const list = $('pair-list');
  list.replaceChildren();
  const invalid = new Set(state.errors.map((e) => e.pair));
  state.pairs.forEach((pair, i) => {
    const item = document.createElement('li');
    item.textContent = `${pair.type} (line ${pair.line})`;
    item.dataset.pair = i + 1;
    if (i + 1 === selected) item.classList.add('selected');
    if (invalid.has(i + 1)) item.classList.add('invalid');
    item.addEventListener('click', () => onSelect(i + 1));
    list.appendChild(item);
  });
}

/** Number fields for the selected pair's type, origins and scales; `onSet(key, value)`. */
export function showFields(state, selected, onSet) {
  const fields = $('fields');
  fields.replaceChildren();
  const pair = state.pairs[selected - 1];
  if (!pair) { fields.textContent = 'none: click a pair, or an element in the view'; return; }
  const type = document.createElement('select');
  const types = state.landmarks ? ['point'] : ['point', 'segment', 'rectangle', 'box'];
  if (!types.includes(pair.type)) types.push(pair.type); // an invalid one stays shown, with its error
  for (const t of types) type.add(new Option(t, t, false, t === pair.type));
  type.addEventListener('change', () => onSet(`pair[${selected}].type`, type.value));
  fields.append(row('type', [type]));
  for (const side of ['source', 'target']) {
    const e = pair[side];
    const head = document.createElement('h2');
    head.textContent = side;
    head.className = side;
    fields.append(head);
    for (const key of ['origin', 'scale']) {
      const inputs = e[key].map((v, i) => {
        const input = document.createElement('input');
        input.type = 'number';
        input.step = '0.01';
        input.value = String(v);
        input.dataset.key = `${side}.${key}.${i}`;
        input.addEventListener('change', () => {
          const value = inputs.map((x) => Number(x.value));
          onSet(`pair[${selected}].${side}.${key}`, value);
        });
        return input;
      });
      fields.append(row(key, inputs));
    }
    const axes = document.createElement('span');
    axes.className = 'axes';
    axes.textContent = `x ${fmt(e.axes[0])}  y ${fmt(e.axes[1])}`;
    fields.append(row('axes', [axes]));
  }
}

function fmt(v) { return `[${v.map((x) => x.toFixed(3)).join(', ')}]`; }

function row(name, children) {
  const div = document.createElement('div');
  div.className = 'field';
  const label = document.createElement('label');
  label.textContent = name;
  div.append(label, ...children);
  return div;
}

export function showErrors(state) {
  const list = $('errors');
  list.replaceChildren();
  if (!state.errors.length) {
    const none = document.createElement('li');
    none.className = 'none';
    none.textContent = 'none';
    list.appendChild(none);
    return;
  }
  for (const e of state.errors) {
    const item = document.createElement('li');
    item.textContent = `${e.where}: ${e.message}`;
    list.appendChild(item);
  }
}

/** Labels over the view: each pair's number beside its element at t, each problem at its element. */
export function showLabels(view, state, atElements) {
  const layer = $('labels');
  layer.replaceChildren();
  const place = (text, point, cls) => {
    const s = view.toScreen(point);
    if (!s.visible) return;
    const r = layer.getBoundingClientRect();
    const label = document.createElement('div');
    label.className = `label ${cls}`;
    label.textContent = text;
    label.style.left = `${s.x - r.left}px`;
    label.style.top = `${s.y - r.top}px`;
    layer.appendChild(label);
  };
  atElements.forEach((e, i) => place(String(i + 1), e.origin, 'number'));
  for (const e of state.errors) {
    const pair = state.pairs[e.pair - 1];
    if (!pair) continue;
    place(e.message, pair[e.side || 'source'].origin, 'error');
  }
}
