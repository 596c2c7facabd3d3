// The page's controls and read-outs: the grid's facts, the slice plane, the overlays' toggles and the cell under
// the pointer (with its signed distance and volume fraction when the grid has them). Plain DOM; the elements have ids
// (vox-...) that tests and users' scripts can rely on.

import { INSIDE_COLOR, OUTSIDE_COLOR, availableFields, distanceLimit } from './field.js';

const css = `
html, body { margin: 0; height: 100%; overflow: hidden; background: #000; }
#vox-canvas { display: block; position: fixed; left: 0; top: 0; }
#vox-panel { position: fixed; left: 8px; top: 8px; max-width: 22em; padding: 8px 10px; border-radius: 6px;
  background: rgba(255, 255, 255, 0.88); color: #111; font: 12px/1.45 system-ui, sans-serif;
  box-shadow: 0 1px 4px rgba(0, 0, 0, 0.3); user-select: none; }
#vox-panel.hidden { display: none; }
#vox-panel h1 { font-size: 13px; margin: 0 0 2px; overflow-wrap: anywhere; }
#vox-panel .row { margin-top: 5px; display: flex; align-items: center; gap: 6px; flex-wrap: wrap; }
#vox-panel input[type=range] { flex: 1; min-width: 8em; }
#vox-panel label { white-space: nowrap; }
#vox-info { margin-top: 6px; padding-top: 5px; border-top: 1px solid #bbb; font-family: ui-monospace, monospace;
  min-height: 2.9em; overflow-wrap: anywhere; }
#vox-legend { flex: 1; min-width: 8em; height: 10px; border: 1px solid #888; }
#vox-help { margin-top: 5px; color: #555; font-size: 11px; }
`;

const fmt = (n) => Number(n).toLocaleString('en-US');
// A field's value as the read-out shows it: the float32 value to 7 significant digits (all it holds).
const fmtValue = (v) => String(Number(v.toPrecision(7)));
const FIELD_NAMES = { distance: 'signed distance', fraction: 'volume fraction', voxels: 'voxel colours' };

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

function checkbox(id, text, checked, onChange) {
  const box = el('input', { type: 'checkbox', id });
  box.checked = checked;
  box.addEventListener('change', () => onChange(box.checked));
  return el('label', { for: id }, box, ` ${text}`);
}

// The slice plane's choice of field and its colour scale, for a grid with signed distances or volume fractions
// (field.js); null for one without.
function fieldRow(data, actions) {
  const fields = availableFields(data);
  if (fields.length < 2) return null;
  const select = el('select', { id: 'vox-slice-field', 'aria-label': 'what the slice plane shows' });
  for (const f of fields) select.append(el('option', { value: f, text: FIELD_NAMES[f] }));
  const legend = el('span', { id: 'vox-legend' });
  const range = el('span', { id: 'vox-legend-range' });
  const rgb = (c) => `rgb(${c.join(',')})`;
  const show = () => {
    const f = select.value;
    legend.style.display = f === 'voxels' ? 'none' : '';
    if (f === 'distance') {
      const limit = fmtValue(distanceLimit(data));
      legend.style.background = `linear-gradient(to right, ${rgb(INSIDE_COLOR)}, #fff, ${rgb(OUTSIDE_COLOR)})`;
      range.textContent = `−${limit} … ${limit}`;
    } else if (f === 'fraction') {
      legend.style.background = 'linear-gradient(to right, #000, #fff)';
      range.textContent = '0 … 1';
    } else {
      range.textContent = '';
    }
  };
  select.addEventListener('change', () => {
    show();
    actions.field(select.value);
  });
  show();
  return el('div', { class: 'row' }, el('label', { for: 'vox-slice-field' }, 'plane: '), select, legend, range);
}

// The read-out's words for a cell's fields: its signed distance (or that it lies outside the band) and fraction.
function fieldText(cell) {
  let text = '';
  if (cell.distance !== undefined)
    text += cell.distance === null ? ' · outside the distance band' : ` · signed distance ${fmtValue(cell.distance)}`;
  if (cell.fraction !== undefined) text += ` · volume fraction ${fmtValue(cell.fraction)}`;
  return text;
}

// actions: {slice(axis, pos, keepBelow), field(name), toggle(what, on), resetCamera()}.
export function buildPanel(data, cells, actions) {
  document.head.append(el('style', { text: css }));
  const [nx, ny, nz] = data.dims;
  const panel = el('div', { id: 'vox-panel' });
  panel.append(el('h1', { id: 'vox-title', text: data.title || 'grid' }));
  const prims = [`${fmt(data.primitiveCount)} primitives`];
  panel.append(
    el('div', {
      id: 'vox-stats',
      text:
        `${nx} × ${ny} × ${nz} cells · ${fmt(data.occupiedCount)} occupied` +
        (data.solidCount ? ` · ${fmt(data.solidCount)} solid` : '') +
        ` · ${prims} · colour: ${data.colorMode}` +
        (data.hasDistances ? ` · signed distances: ${fmt(data.bandCount)} band cells` : '') +
        (data.hasFractions ? ' · volume fractions' : '') +
        (data.hasLevelSurface ? ` · surface d = 0: ${fmt(data.levelTriangleCount)} triangles` : ''),
    }),
  );

  // Slice: axis, plane position (a lattice plane, 0..n), which side stays.
  const axisSelect = el('select', { id: 'vox-slice-axis', 'aria-label': 'slice axis' });
  for (const [v, t] of [
    ['-1', 'no slice'],
    ['0', 'slice x'],
    ['1', 'slice y'],
    ['2', 'slice z'],
  ])
    axisSelect.append(el('option', { value: v, text: t }));
  const slider = el('input', { type: 'range', id: 'vox-slice', min: '0', max: '1', step: '1', value: '0' });
  slider.disabled = true;
  const sliceValue = el('span', { id: 'vox-slice-value', text: '' });
  const flip = el('input', { type: 'checkbox', id: 'vox-slice-flip' });
  const apply = () => {
    const axis = Number(axisSelect.value);
    actions.slice(axis, Number(slider.value), !flip.checked);
    sliceValue.textContent = axis < 0 ? '' : `${'xyz'[axis]} ${flip.checked ? '≥' : '<'} ${slider.value}`;
  };
  axisSelect.addEventListener('change', () => {
    const axis = Number(axisSelect.value);
    slider.disabled = axis < 0;
    if (axis >= 0) {
      const n = data.dims[axis];
      slider.max = String(n);
      slider.value = String(flip.checked ? 0 : n);
    }
    apply();
  });
  slider.addEventListener('input', apply);
  flip.addEventListener('change', apply);
  panel.append(
    el('div', { class: 'row' }, axisSelect, slider, sliceValue),
    el('div', { class: 'row' }, el('label', { for: 'vox-slice-flip' }, flip, ' keep the far side')),
  );
  const fields = fieldRow(data, actions);
  if (fields) panel.append(fields);
  const shown = el('div', { id: 'vox-shown' });
  panel.append(shown);

  panel.append(
    el(
      'div',
      { class: 'row' },
      checkbox('vox-show-voxels', 'voxels', true, (on) => actions.toggle('voxels', on)),
      checkbox('vox-show-triangles', 'triangles', false, (on) => actions.toggle('triangles', on)),
      checkbox('vox-show-bounds', 'bounds', true, (on) => actions.toggle('bounds', on)),
      checkbox('vox-show-lines', 'cell lines', false, (on) => actions.toggle('lines', on)),
      // The level surface d = 0 (vox-export --surface), on pages of grids with distances.
      ...(data.hasLevelSurface && data.levelTriangleCount > 0
        ? [checkbox('vox-show-level', 'surface (d = 0)', false, (on) => actions.toggle('level', on))]
        : []),
    ),
  );
  const reset = el('button', { id: 'vox-reset', type: 'button', text: 'file camera' });
  reset.addEventListener('click', () => actions.resetCamera());
  const info = el('div', { id: 'vox-info', text: 'point at a voxel' });
  panel.append(info);
  panel.append(
    el(
      'div',
      { id: 'vox-help' },
      'drag: orbit · right-drag or shift-drag: pan · wheel: zoom · click: pin a cell · h: hide · ',
      reset,
    ),
  );
  document.body.append(panel);

  return {
    setShown(n, total) {
      shown.textContent = `voxels shown: ${fmt(n)} of ${fmt(total)}`;
      shown.dataset.shown = String(n);
      shown.dataset.total = String(total);
    },
    setCell(cell, pinned) {
      if (!cell) {
        info.textContent = 'point at a voxel';
        delete info.dataset.ijk;
        delete info.dataset.count;
        delete info.dataset.ids;
        delete info.dataset.distance;
        delete info.dataset.fraction;
        return;
      }
      const [i, j, k] = cell.ijk;
      let text = `${pinned ? 'pinned ' : ''}cell (${i}, ${j}, ${k}): `;
      if (cell.occupied) {
        text += `${fmt(cell.count)} primitive${cell.count === 1 ? '' : 's'}`;
        if (cell.ids.length)
          text += `, ${cell.ids.length < cell.count ? `first ${cell.ids.length} ` : ''}id${
            cell.ids.length === 1 ? '' : 's'
          } ${cell.ids.join(', ')}`;
      } else if (cell.solid) {
        text += 'solid (inside, no primitive)';
      } else {
        text += 'empty';
      }
      text += fieldText(cell);
      info.textContent = text;
      info.dataset.ijk = `${i},${j},${k}`;
      info.dataset.count = String(cell.count);
      info.dataset.ids = cell.ids.join(',');
      info.dataset.solid = cell.solid ? '1' : '0';
      // The values as the page holds them (float32, all digits): tests compare them with the grid's.
      if (cell.distance !== undefined) info.dataset.distance = cell.distance === null ? '' : String(cell.distance);
      if (cell.fraction !== undefined) info.dataset.fraction = String(cell.fraction);
    },
    toggleHidden() {
      panel.classList.toggle('hidden');
    },
    setHidden(hidden) {
      panel.classList.toggle('hidden', hidden);
    },
  };
}
