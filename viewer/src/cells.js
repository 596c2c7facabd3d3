// The grid's voxels as the page sees them (decoded layout from data.js): which cell is occupied or solid, what it
// holds, how many voxels lie on each side of a slice, the faces that close a cut, and the first voxel along a ray.
// Lattice space: cell (i, j, k) is the box [i, i+1] x [j, j+1] x [k, k+1]; it maps to world space by
// lo + (hi - lo) * x / dims on each axis (cellBoundary in libvox).

// Index of the first element of `array[from, to)` that is >= value.
function lowerBound(array, from, to, value) {
  while (from < to) {
    const mid = (from + to) >>> 1;
    if (array[mid] < value) from = mid + 1;
    else to = mid;
  }
  return from;
}

// The cells of a row table (the occupied cells, or the signed-distance band): rows j + ny * k ascending, row r
// holding cells [start r, start r+1), each cell's i. The cell's index in the table at (i, j, k), or -1.
function indexInRows(t, ny, i, j, k) {
  const row = j + ny * k;
  const r = lowerBound(t.keys, 0, t.count, row);
  if (r === t.count || t.keys[r] !== row) return -1;
  const c = lowerBound(t.i, t.start[r], t.start[r + 1], i);
  return c < t.start[r + 1] && t.i[c] === i ? c : -1;
}

// Calls fn(i, j, k, c) for every cell of table `t` in layer `l` on `axis` (c: the cell's index in the table).
function forEachRowCellInLayer(t, ny, axis, l, fn) {
  if (axis === 2) {
    const r0 = lowerBound(t.keys, 0, t.count, ny * l);
    for (let r = r0; r < t.count && t.keys[r] < ny * (l + 1); ++r) {
      const j = t.keys[r] - ny * l;
      for (let c = t.start[r]; c < t.start[r + 1]; ++c) fn(t.i[c], j, l, c);
    }
    return;
  }
  for (let r = 0; r < t.count; ++r) {
    const row = t.keys[r];
    const j = row % ny;
    const k = (row - j) / ny;
    if (axis === 1) {
      if (j !== l) continue;
      for (let c = t.start[r]; c < t.start[r + 1]; ++c) fn(t.i[c], j, k, c);
    } else {
      const c = lowerBound(t.i, t.start[r], t.start[r + 1], l);
      if (c < t.start[r + 1] && t.i[c] === l) fn(l, j, k, c);
    }
  }
}

export class Cells {
  constructor(d) {
    this.d = d;
    this.dims = d.dims;
    this.occupiedRows = { keys: d.rowKeys, start: d.rowStart, i: d.cellI, count: d.rowCount };
    this.bandRows = d.hasDistances
      ? { keys: d.bandRowKeys, start: d.bandRowStart, i: d.bandI, count: d.bandRowCount }
      : null;
    const [nx, ny, nz] = d.dims;
    this.total = d.occupiedCount + d.solidCount;
    // Voxels per layer along each axis, occupied and solid, and their prefix sums: the count on either side of a
    // slice in O(1).
    const hist = [new Float64Array(nx + 1), new Float64Array(ny + 1), new Float64Array(nz + 1)];
    for (let r = 0; r < d.rowCount; ++r) {
      const row = d.rowKeys[r];
      const j = row % ny;
      const k = (row - j) / ny;
      const n = d.rowStart[r + 1] - d.rowStart[r];
      hist[1][j] += n;
      hist[2][k] += n;
    }
    for (let c = 0; c < d.occupiedCount; ++c) hist[0][d.cellI[c]] += 1;
    const diffX = new Float64Array(nx + 1);
    this.forEachSolidSegment((i0, i1, j, k) => {
      const n = i1 - i0 + 1;
      hist[1][j] += n;
      hist[2][k] += n;
      diffX[i0] += 1;
      diffX[i1 + 1] -= 1;
    });
    for (let i = 0, run = 0; i < nx; ++i) {
      run += diffX[i];
      hist[0][i] += run;
    }
    this.below = hist.map((h, a) => {
      const p = new Float64Array(d.dims[a] + 1);
      for (let l = 0; l < d.dims[a]; ++l) p[l + 1] = p[l] + h[l];
      return p;
    });
  }

  // Calls fn(i0, i1, j, k) for each piece of a solid run inside one row (cells i0..i1 of row j, k).
  forEachSolidSegment(fn) {
    const d = this.d;
    const [nx, ny] = this.dims;
    for (let r = 0; r < d.solidRunCount; ++r) {
      const first = d.solidRuns[2 * r];
      const last = first + d.solidRuns[2 * r + 1] - 1;
      for (let row = Math.floor(first / nx); row <= Math.floor(last / nx); ++row) {
        const i0 = Math.max(first - row * nx, 0);
        const i1 = Math.min(last - row * nx, nx - 1);
        const j = row % ny;
        fn(i0, i1, j, (row - j) / ny);
      }
    }
  }

  // The occupied cell's index (in key order) at (i, j, k), or -1.
  occupiedIndex(i, j, k) {
    return indexInRows(this.occupiedRows, this.dims[1], i, j, k);
  }

  // The band cell's index (in key order) at (i, j, k), or -1 (no band, or the cell is outside it).
  bandIndex(i, j, k) {
    return this.bandRows ? indexInRows(this.bandRows, this.dims[1], i, j, k) : -1;
  }

  // Calls fn(i, j, k, b) for every band cell of layer `l` on `axis` (b: its index in the band).
  forEachBandInLayer(axis, l, fn) {
    if (this.bandRows) forEachRowCellInLayer(this.bandRows, this.dims[1], axis, l, fn);
  }

  isSolid(i, j, k) {
    const d = this.d;
    if (d.solidRunCount === 0) return false;
    const key = i + this.dims[0] * (j + this.dims[1] * k);
    // The last run starting at or before key.
    let lo = 0;
    let hi = d.solidRunCount;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (d.solidRuns[2 * mid] <= key) lo = mid + 1;
      else hi = mid;
    }
    if (lo === 0) return false;
    const r = lo - 1;
    return key < d.solidRuns[2 * r] + d.solidRuns[2 * r + 1];
  }

  inside(i, j, k) {
    return i >= 0 && j >= 0 && k >= 0 && i < this.dims[0] && j < this.dims[1] && k < this.dims[2];
  }

  isVoxel(i, j, k) {
    return this.inside(i, j, k) && (this.occupiedIndex(i, j, k) >= 0 || this.isSolid(i, j, k));
  }

  // What the page shows of cell (i, j, k): {ijk, occupied, solid, count, ids (the stored first ones)}, and when the
  // grid has them `distance` (the band's float32 value, null outside the band) and `fraction` (solid cells 1, empty
  // ones 0).
  info(i, j, k) {
    const d = this.d;
    const c = this.occupiedIndex(i, j, k);
    let cell;
    if (c < 0) {
      cell = { ijk: [i, j, k], occupied: false, solid: this.isSolid(i, j, k), count: 0, ids: [] };
    } else {
      const ids = Array.from(d.ids.subarray(d.idStart[c], d.idStart[c + 1]));
      cell = { ijk: [i, j, k], occupied: true, solid: false, count: d.cellCount[c], ids, index: c };
    }
    if (d.hasDistances) {
      const b = this.bandIndex(i, j, k);
      cell.distance = b < 0 ? null : d.distances[b];
    }
    if (d.hasFractions) cell.fraction = c >= 0 ? d.fractions[c] : cell.solid ? 1 : 0;
    return cell;
  }

  // sRGB bytes of occupied cell c, or of the solid cells (c < 0); null without colours.
  color(c) {
    const d = this.d;
    if (!d.hasColors) return null;
    if (c < 0) return d.solidColor;
    const p = d.cellColor[c];
    return [d.palette[3 * p], d.palette[3 * p + 1], d.palette[3 * p + 2]];
  }

  // Voxels kept by a slice on `axis` at lattice plane `pos` (0..dims[axis]): those below it (index < pos) when
  // keepBelow, else those at or above it.
  keptCount(axis, pos, keepBelow) {
    if (axis < 0) return this.total;
    const below = this.below[axis][pos];
    return keepBelow ? below : this.total - below;
  }

  // Calls fn(i, j, k, c) for every voxel of layer `l` on `axis` (c: occupied index, or -1 for a solid cell).
  forEachInLayer(axis, l, fn) {
    forEachRowCellInLayer(this.occupiedRows, this.dims[1], axis, l, fn);
    this.forEachSolidSegment((i0, i1, j, k) => {
      if (axis === 0) {
        if (l >= i0 && l <= i1) fn(l, j, k, -1);
      } else if ((axis === 1 ? j : k) === l) {
        for (let i = i0; i <= i1; ++i) fn(i, j, k, -1);
      }
    });
  }

  // The faces that close a cut on `axis` at plane `pos`: one unit square on the plane for each kept voxel next to
  // the plane whose neighbour across it is a voxel (the surface has no face there). Counter-clockwise seen from the
  // removed side. Returns {positions: Float32Array (lattice), colors: Uint8Array | null, count}.
  capFaces(axis, pos, keepBelow) {
    const n = this.dims[axis];
    const empty = { positions: new Float32Array(0), colors: null, count: 0 };
    if (axis < 0 || pos <= 0 || pos >= n) return empty;
    const layer = keepBelow ? pos - 1 : pos;
    const other = keepBelow ? pos : pos - 1;
    const quads = [];
    this.forEachInLayer(axis, layer, (i, j, k, c) => {
      const q = [i, j, k];
      q[axis] = other;
      if (this.isVoxel(q[0], q[1], q[2])) quads.push(i, j, k, c);
    });
    const count = quads.length / 4;
    const positions = new Float32Array(count * 18);
    const colors = this.d.hasColors ? new Uint8Array(count * 18) : null;
    const b = (axis + 1) % 3;
    const c2 = (axis + 2) % 3;
    for (let f = 0; f < count; ++f) {
      const cell = [quads[4 * f], quads[4 * f + 1], quads[4 * f + 2]];
      const corner = (db, dc) => {
        const p = [0, 0, 0];
        p[axis] = pos;
        p[b] = cell[b] + db;
        p[c2] = cell[c2] + dc;
        return p;
      };
      // e_b x e_c = e_axis: (0,0) (1,0) (1,1) (0,1) turns counter-clockwise seen from +axis.
      let corners = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 0), corner(1, 1), corner(0, 1)];
      if (!keepBelow) corners = [corners[0], corners[2], corners[1], corners[3], corners[5], corners[4]];
      corners.forEach((p, v) => positions.set(p, 18 * f + 3 * v));
      if (colors) {
        const rgb = this.color(quads[4 * f + 3]);
        for (let v = 0; v < 6; ++v) colors.set(rgb, 18 * f + 3 * v);
      }
    }
    return { positions, colors, count };
  }

  // The first voxel that a ray meets (origin and direction as firstCell's); `keep(i, j, k)` says whether a voxel is
  // drawn (the slice).
  firstVoxel(origin, dir, keep = () => true) {
    return this.firstCell(origin, dir, (i, j, k) => this.isVoxel(i, j, k) && keep(i, j, k));
  }

  // The first cell for which `hit(i, j, k)` holds along a ray, walking the cells front to back (Amanatides and Woo
  // 1987) from the ray's origin (lattice space; direction need not be unit): voxels, or the cells the slice plane
  // shows a field on. Returns {ijk, t, axis (entry face's axis, -1 when the ray starts inside)} or null.
  firstCell(origin, dir, hit) {
    const n = this.dims;
    let t0 = 0;
    let t1 = Infinity;
    for (let a = 0; a < 3; ++a) {
      if (dir[a] === 0) {
        if (origin[a] < 0 || origin[a] > n[a]) return null;
        continue;
      }
      let ta = (0 - origin[a]) / dir[a];
      let tb = (n[a] - origin[a]) / dir[a];
      if (ta > tb) [ta, tb] = [tb, ta];
      t0 = Math.max(t0, ta);
      t1 = Math.min(t1, tb);
    }
    if (!(t0 <= t1)) return null;
    const cell = [0, 0, 0];
    const step = [0, 0, 0];
    const tMax = [Infinity, Infinity, Infinity];
    const tDelta = [Infinity, Infinity, Infinity];
    let axis = -1;
    for (let a = 0; a < 3; ++a) {
      const p = origin[a] + dir[a] * t0;
      cell[a] = Math.min(Math.max(Math.floor(p), 0), n[a] - 1);
      if (dir[a] > 0) {
        step[a] = 1;
        tMax[a] = (cell[a] + 1 - origin[a]) / dir[a];
        tDelta[a] = 1 / dir[a];
      } else if (dir[a] < 0) {
        step[a] = -1;
        tMax[a] = (cell[a] - origin[a]) / dir[a];
        tDelta[a] = -1 / dir[a];
      }
    }
    if (t0 > 0) {
      // The entry face: the axis whose slab the ray entered last.
      let best = -Infinity;
      for (let a = 0; a < 3; ++a) {
        if (dir[a] === 0) continue;
        const ta = Math.min((0 - origin[a]) / dir[a], (n[a] - origin[a]) / dir[a]);
        if (ta > best) [best, axis] = [ta, a];
      }
    }
    let t = t0;
    for (let steps = n[0] + n[1] + n[2] + 3; steps > 0; --steps) {
      if (hit(cell[0], cell[1], cell[2])) return { ijk: cell.slice(), t, axis };
      let a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : tMax[1] < tMax[2] ? 1 : 2;
      t = tMax[a];
      if (t > t1) return null;
      cell[a] += step[a];
      if (cell[a] < 0 || cell[a] >= n[a]) return null;
      tMax[a] += tDelta[a];
      axis = a;
    }
    return null;
  }
}
