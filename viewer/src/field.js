// What the slice plane shows of the grid's fields (issue 38): the signed distance of each band cell on a diverging
// map (blue inside, white on the surface, red outside), or each voxel's volume fraction as its grey level. The cells
// are those of the kept layer next to the plane; the quads lie on the plane, drawn over the voxels' faces there.

// The map's ends, sRGB bytes (the ends of Moreland's cool-warm map): negative (inside) and positive (outside).
export const INSIDE_COLOR = [59, 76, 192];
export const OUTSIDE_COLOR = [180, 4, 38];

// sRGB bytes of signed distance `value` (world units) on a map clamped at +-limit: white at 0, each end at the limit.
export function distanceColor(value, limit) {
  const t = Math.min(Math.abs(value) / limit, 1);
  const end = value < 0 ? INSIDE_COLOR : OUTSIDE_COLOR;
  return end.map((e) => Math.round(255 + (e - 255) * t));
}

// sRGB bytes of volume fraction `f` in [0, 1]: black empty, white full.
export function fractionColor(f) {
  const g = Math.round(Math.min(Math.max(f, 0), 1) * 255);
  return [g, g, g];
}

// The fields this grid can show on the slice plane, the first being the page's default: 'distance', 'fraction',
// then 'voxels' (the cells' own colours, the plane drawn as without fields).
export function availableFields(d) {
  const fields = [];
  if (d.hasDistances) fields.push('distance');
  if (d.hasFractions) fields.push('fraction');
  fields.push('voxels');
  return fields;
}

// The distance at which the map reaches its ends: the band's half-width in smallest cell edges, in world units.
export function distanceLimit(d) {
  const edge = Math.min(...[0, 1, 2].map((a) => (d.hi[a] - d.lo[a]) / d.dims[a]));
  return d.halfWidth * edge;
}

// The layer of cells a slice on `axis` at plane `pos` keeps next to the plane, or -1 when it keeps none.
export function keptLayer(dims, axis, pos, keepBelow) {
  if (axis < 0) return -1;
  const layer = keepBelow ? pos - 1 : pos;
  return layer >= 0 && layer < dims[axis] ? layer : -1;
}

// Calls fn(i, j, k, rgb) for every cell that `field` colours in layer `layer` on `axis`: the band's cells
// ('distance'), or the voxels ('fraction', solid cells 1).
function forEachFieldCell(cells, field, axis, layer, fn) {
  const d = cells.d;
  if (field === 'distance') {
    const limit = distanceLimit(d);
    cells.forEachBandInLayer(axis, layer, (i, j, k, b) => fn(i, j, k, distanceColor(d.distances[b], limit)));
  } else if (field === 'fraction') {
    cells.forEachInLayer(axis, layer, (i, j, k, c) => fn(i, j, k, fractionColor(c < 0 ? 1 : d.fractions[c])));
  }
}

// Whether the slice plane shows `field` on cell (i, j, k) of the kept layer `layer` (hit test of the read-out).
export function showsField(cells, field, axis, layer, i, j, k) {
  if (layer < 0 || [i, j, k][axis] !== layer) return false;
  if (field === 'distance') return cells.bandIndex(i, j, k) >= 0;
  if (field === 'fraction') return cells.isVoxel(i, j, k);
  return false;
}

// The quads of `field` on the slice plane (axis, pos): one unit square per coloured cell of the kept layer, on the
// plane. Returns {positions: Float32Array (lattice), colors: Uint8Array (sRGB bytes), count}.
export function fieldQuads(cells, field, axis, pos, keepBelow) {
  const layer = keptLayer(cells.dims, axis, pos, keepBelow);
  const quads = [];
  if (layer >= 0) forEachFieldCell(cells, field, axis, layer, (i, j, k, rgb) => quads.push([i, j, k], rgb));
  const count = quads.length / 2;
  const positions = new Float32Array(count * 18);
  const colors = new Uint8Array(count * 18);
  const b = (axis + 1) % 3;
  const c = (axis + 2) % 3;
  for (let f = 0; f < count; ++f) {
    const cell = quads[2 * f];
    const corner = (db, dc) => {
      const p = [0, 0, 0];
      p[axis] = pos;
      p[b] = cell[b] + db;
      p[c] = cell[c] + dc;
      return p;
    };
    [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 0), corner(1, 1), corner(0, 1)].forEach((p, v) => {
      positions.set(p, 18 * f + 3 * v);
      colors.set(quads[2 * f + 1], 18 * f + 3 * v);
    });
  }
  return { positions, colors, count };
}
