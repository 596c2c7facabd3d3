// A coarse stand-in for large grids: the voxels pooled into blocks of f^3 cells (a block is drawn when any of its
// cells is a voxel), as the exposed faces of the blocks. The page draws it for its first frame and while the camera
// moves, then the full surface once the camera rests, so that a grid of millions of cells stays interactive even
// with software GL. Vertices are in the full lattice's units (block corners times f, clamped to the grid), so the
// surface's material, slice and picking apply unchanged.

// f: the smallest power of two that brings the blocks' faces under `budget` triangles, estimated from the full
// surface (faces shrink about as f^2).
export function blockFactor(triangles, budget) {
  let f = 1;
  while (triangles / (f * f) > budget) f *= 2;
  return f;
}

// Returns {lattice: Float32Array (6 vertices per face), colors: Uint8Array | null, faces} for block size f.
export function blockSurface(cells, f) {
  const d = cells.d;
  const dims = d.dims;
  const n = dims.map((x) => Math.ceil(x / f));
  const count = n[0] * n[1] * n[2];
  // The block's colour: its first voxel's (palette index + 1; 0 = empty; solid cells use the last index).
  const block = new Uint32Array(count);
  const solidTag = (d.paletteCount || 0) + 1;
  const ny = dims[1];
  for (let r = 0; r < d.rowCount; ++r) {
    const j = d.rowKeys[r] % ny;
    const k = (d.rowKeys[r] - j) / ny;
    const base = n[0] * (Math.floor(j / f) + n[1] * Math.floor(k / f));
    for (let c = d.rowStart[r]; c < d.rowStart[r + 1]; ++c) {
      const b = base + Math.floor(d.cellI[c] / f);
      if (block[b] === 0) block[b] = d.hasColors ? d.cellColor[c] + 1 : 1;
    }
  }
  cells.forEachSolidSegment((i0, i1, j, k) => {
    const base = n[0] * (Math.floor(j / f) + n[1] * Math.floor(k / f));
    for (let bi = Math.floor(i0 / f); bi <= Math.floor(i1 / f); ++bi) if (block[base + bi] === 0) block[base + bi] = solidTag;
  });
  const filled = (i, j, k) =>
    i >= 0 && j >= 0 && k >= 0 && i < n[0] && j < n[1] && k < n[2] && block[i + n[0] * (j + n[1] * k)] !== 0;
  const positions = [];
  const colors = [];
  const rgb = (tag) => (tag === solidTag ? d.solidColor : cells.color(tag - 1));
  const corner = (p) => p.map((x, a) => Math.min(x * f, dims[a]));
  for (let k = 0; k < n[2]; ++k)
    for (let j = 0; j < n[1]; ++j)
      for (let i = 0; i < n[0]; ++i) {
        const tag = block[i + n[0] * (j + n[1] * k)];
        if (tag === 0) continue;
        const cell = [i, j, k];
        for (let a = 0; a < 3; ++a)
          for (const s of [-1, 1]) {
            const q = cell.slice();
            q[a] += s;
            if (filled(q[0], q[1], q[2])) continue;
            // The face on plane cell[a] (+1 when s > 0), counter-clockwise seen from outside.
            const b = (a + 1) % 3;
            const c = (a + 2) % 3;
            const at = (db, dc) => {
              const p = cell.slice();
              p[a] += s > 0 ? 1 : 0;
              p[b] += db;
              p[c] += dc;
              return corner(p);
            };
            let quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 0), at(1, 1), at(0, 1)];
            if (s < 0) quad = [quad[0], quad[2], quad[1], quad[3], quad[5], quad[4]];
            for (const p of quad) positions.push(p[0], p[1], p[2]);
            if (d.hasColors) {
              const col = rgb(tag);
              for (let v = 0; v < 6; ++v) colors.push(col[0], col[1], col[2]);
            }
          }
      }
  return {
    lattice: new Float32Array(positions),
    colors: d.hasColors ? new Uint8Array(colors) : null,
    faces: positions.length / 18,
  };
}
