// The page's side of the binary layout, under Node (no browser): viewer/src/data.js reads what vox-export wrote into
// the page, and viewer/src/cells.js answers from it what vox-info says of the same grid (cells, counts, first ids,
// solid cells, counts per slice). Also the hash's parsing and vox-trace's camera rules (viewer/src/camera.js).
// The C++ side of the layout is tested by tests/viewer_page_test.cpp.
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

import { check, finish, info, pageData, scratch, source, tool } from './lib.mjs';

const viewerSrc = (name) => pathToFileURL(join(source, 'viewer', 'src', name)).href;
const { decodeViewerData, layoutFromElements, LayoutError } = await import(viewerSrc('data.js'));
const { Cells } = await import(viewerSrc('cells.js'));
const { blockSurface } = await import(viewerSrc('lod.js'));
const { parseHash, formatHash, resolveCamera, verticalView } = await import(viewerSrc('camera.js'));

const dir = scratch('data');
const grids = [];
const bunny = join(source, 'scenes', 'bunny_1k.obj');
tool('vox-voxelize', bunny, '-o', join(dir, 'bunny.vgrid'), '--grid', '21', '17', '13', '--fill', '--quiet');
grids.push({ name: 'bunny filled', grid: 'bunny.vgrid', solidCut: true, spanLonger: false });
tool('vox-voxelize', join(source, 'scenes', 'scene5_02_spheres.txt'), '-o', join(dir, 'spheres.vgrid'), '--res', '30',
  '--quiet');
grids.push({ name: 'spheres', grid: 'spheres.vgrid', spanLonger: true });  // a course camera

for (const g of grids) {
  const grid = join(dir, g.grid);
  const html = join(dir, `${g.grid}.html`);
  tool('vox-export', grid, '-o', html, '--quiet');
  const d = decodeViewerData(await layoutFromElements(pageData(html)));
  const facts = info(grid, '--cells', '--primitives');
  check(d.dims.join() === facts.dims.join(), `${g.name}: dims ${d.dims}`);
  check(
    d.lo.every((x, a) => x === facts.bounds.min[a]) && d.hi.every((x, a) => x === facts.bounds.max[a]),
    `${g.name}: bounds exactly vox-info's`,
  );
  check(d.title === g.grid, `${g.name}: title ${d.title}`);
  check(d.camera.spanLonger === g.spanLonger, `${g.name}: the camera spans the ${g.spanLonger ? 'longer side' : 'height'}`);
  const cells = new Cells(d);
  let same = facts.cells.length === d.occupiedCount;
  for (const c of facts.cells) {
    const got = cells.info(...c.ijk);
    if (!got.occupied || got.count !== c.prims.length || got.ids.join() !== c.prims.slice(0, d.idsPerCell).join()) {
      same = false;
      console.log(`  cell ${c.ijk}: page ${JSON.stringify(got)}, vox-info ${c.prims}`);
      break;
    }
  }
  check(same, `${g.name}: ${facts.cells.length} cells with their counts and first ids as vox-info lists them`);
  check(d.solidCount === (facts.solid_cells ?? 0), `${g.name}: ${d.solidCount} solid cells`);
  check(d.primitiveCount === facts.primitives.length, `${g.name}: ${d.primitiveCount} primitives`);
  // Every cell of the lattice: a voxel in the page exactly when occupied in vox-info or solid; per-axis counts.
  const occupied = new Set(facts.cells.map((c) => c.ijk.join()));
  let voxels = 0;
  let wrong = 0;
  const perAxisBelow = [0, 1, 2].map((a) => new Float64Array(d.dims[a] + 1));
  for (let k = 0; k < d.dims[2]; ++k)
    for (let j = 0; j < d.dims[1]; ++j)
      for (let i = 0; i < d.dims[0]; ++i) {
        const v = cells.isVoxel(i, j, k);
        if (occupied.has(`${i},${j},${k}`) && !v) ++wrong;
        if (v) {
          ++voxels;
          [i, j, k].forEach((x, a) => {
            perAxisBelow[a][x + 1] += 1;
          });
        }
      }
  check(wrong === 0 && voxels === facts.cells.length + d.solidCount, `${g.name}: ${voxels} voxels in the lattice`);
  let slices = true;
  for (let a = 0; a < 3; ++a) {
    for (let s = 0, acc = 0; s <= d.dims[a]; ++s) {
      acc += perAxisBelow[a][s];
      if (cells.keptCount(a, s, true) !== acc || cells.keptCount(a, s, false) !== voxels - acc) slices = false;
    }
  }
  check(slices, `${g.name}: the voxels kept on either side of every slice plane`);
  // The cut's faces: one per kept voxel next to the plane whose neighbour across it is a voxel.
  const axis = 0;
  const pos = d.dims[0] >> 1;
  let want = 0;
  for (let k = 0; k < d.dims[2]; ++k)
    for (let j = 0; j < d.dims[1]; ++j) if (cells.isVoxel(pos - 1, j, k) && cells.isVoxel(pos, j, k)) ++want;
  const caps = cells.capFaces(axis, pos, true);
  check(caps.count === want && (want > 0) === !!g.solidCut, `${g.name}: ${caps.count} faces close the cut at x = ${pos} (want ${want})`);
  // A ray along z through a column holding a cell meets the first voxel of that column.
  const column = facts.cells[facts.cells.length >> 1].ijk;
  const o = [column[0] + 0.3, column[1] + 0.6, -3];
  const hit = cells.firstVoxel(o, [0, 0, 1]);
  let first = null;
  for (let k = 0; k < d.dims[2] && !first; ++k)
    if (cells.isVoxel(Math.floor(o[0]), Math.floor(o[1]), k)) first = [Math.floor(o[0]), Math.floor(o[1]), k];
  check(JSON.stringify(hit?.ijk ?? null) === JSON.stringify(first), `${g.name}: the ray meets ${first}`);
  // The surface's vertices lie on the lattice; the triangles index them.
  let inRange = true;
  for (let v = 0; v < d.vertexCount && inRange; ++v)
    for (let a = 0; a < 3; ++a) if (d.vertices[3 * v + a] > d.dims[a]) inRange = false;
  for (const t of d.triangles) if (t >= d.vertexCount) inRange = false;
  check(inRange && d.triangleCount > 0, `${g.name}: ${d.triangleCount} surface triangles on the lattice`);
  // The surface's area (lattice units) is the number of exposed unit squares, which the stand-in of blocks of one
  // cell draws one by one; blocks of 2 and 3: their exposed faces, counted here cell by cell.
  let area2 = 0;
  for (let t = 0; t < d.triangleCount; ++t) {
    const p = [0, 1, 2].map((c) => [0, 1, 2].map((a) => d.vertices[3 * d.triangles[3 * t + c] + a]));
    const e1 = p[1].map((x, a) => x - p[0][a]);
    const e2 = p[2].map((x, a) => x - p[0][a]);
    area2 += Math.hypot(e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]);
  }
  check(blockSurface(cells, 1).faces === area2 / 2, `${g.name}: blocks of 1 cell: ${area2 / 2} exposed squares`);
  for (const f of [2, 3]) {
    const n = d.dims.map((x) => Math.ceil(x / f));
    const full = new Set();
    for (let k = 0; k < d.dims[2]; ++k)
      for (let j = 0; j < d.dims[1]; ++j)
        for (let i = 0; i < d.dims[0]; ++i)
          if (cells.isVoxel(i, j, k)) full.add(`${Math.floor(i / f)},${Math.floor(j / f)},${Math.floor(k / f)}`);
    let faces = 0;
    for (const key of full) {
      const b = key.split(',').map(Number);
      for (let a = 0; a < 3; ++a)
        for (const s of [-1, 1]) {
          const q = b.slice();
          q[a] += s;
          if (q[a] < 0 || q[a] >= n[a] || !full.has(q.join())) ++faces;
        }
    }
    check(blockSurface(cells, f).faces === faces, `${g.name}: blocks of ${f}^3: ${faces} exposed faces`);
  }
}

// A damaged layout is refused with a reason, not drawn.
{
  const elements = pageData(join(dir, 'bunny.vgrid.html'));
  check(elements.length === 1 && elements[0].encoding === 'deflate', 'the page holds its data deflated');
  const bytes = await layoutFromElements(elements);
  try {
    await layoutFromElements([{ ...elements[0], text: elements[0].text.slice(0, elements[0].text.length >> 1) }]);
    check(false, 'a cut deflated stream: refused');
  } catch (e) {
    check(e instanceof LayoutError, `a cut deflated stream: refused (${e.message})`);
  }
  const expectThrow = (mutate, what) => {
    const copy = bytes.slice();
    const cut = mutate(copy);
    try {
      decodeViewerData(cut ?? copy);
      check(false, `${what}: refused`);
    } catch (e) {
      check(e instanceof LayoutError, `${what}: refused (${e.message})`);
    }
  };
  expectThrow((b) => b.subarray(0, b.length - 8).slice(), 'a truncated layout');
  expectThrow((b) => {
    b[0] = 0x58;
  }, 'a wrong magic');
  expectThrow((b) => {
    b[8] = 2;
  }, 'another version');
}

// The hash.
{
  const h = parseHash('#eye=1,2,3&look=0,0.5,-1e-3&up=0,0,1&fov=35.5');
  check(
    h.eye.join() === '1,2,3' && h.look.join() === '0,0.5,-0.001' && h.up.join() === '0,0,1' && h.fov === 35.5,
    'parseHash reads eye, look, up and fov',
  );
  const round = parseHash(formatHash({ eye: [1 / 3, -2, 1e-7], look: [0, 0, 0], up: [0, 1, 0], fov: 40 }));
  check(Math.abs(round.eye[0] - 1 / 3) < 1e-8 && round.eye[2] === 1e-7, 'formatHash keeps 9 digits');
  check(parseHash('') === null && parseHash('#') === null, 'no hash: the file camera');
  for (const bad of ['#eye=1,2&look=0,0,0', '#eye=1,2,3', '#eye=1,2,3&look=0,0,0&fov=180', '#fov=abc', '#up=1,,2'])
    try {
      parseHash(bad);
      check(false, `${bad} refused`);
    } catch (e) {
      check(/^hash: /.test(e.message), `${bad} refused (${e.message})`);
    }
  // vox-trace's rules: eye and look keep the file camera's up and fov (45 for an orthographic one).
  const file = { orthographic: false, eye: [0, 0, 5], direction: [0, 0, -2], up: [0, 1, 0], fov: 30, orthoHeight: 2 };
  let cam = resolveCamera(file, parseHash('#eye=1,1,1&look=0,0,0'), [0, 0, 0]);
  check(cam.fov === 30 && cam.up.join() === '0,1,0' && !cam.orthographic, 'eye and look keep the file fov and up');
  cam = resolveCamera({ ...file, orthographic: true }, parseHash('#eye=1,1,1&look=0,0,0'), [0, 0, 0]);
  check(cam.fov === 45 && !cam.orthographic, 'eye and look over an orthographic camera: fov 45, perspective');
  cam = resolveCamera(file, null, [0, 0, 1]);
  check(cam.eye.join() === '0,0,5' && cam.look.join() === '0,0,1', 'the file camera orbits the grid centre');
  cam = resolveCamera(file, parseHash('#fov=60'), [0, 0, 0]);
  check(cam.fov === 60 && cam.eye.join() === '0,0,5', 'fov alone changes the file camera');
  // A course camera spans the image's longer side, as vox-trace renders it: on a 2:1 page its 60 degrees are across
  // the width, so the vertical angle has tan(half) = tan(30) / 2; on a tall page, and for DESIGN.md's cameras, the
  // angle stays vertical. The hash's fov is vertical (vox-trace's --fov), so it ends the span.
  const course = { ...file, fov: 60, spanLonger: true };
  cam = resolveCamera(course, null, [0, 0, 0]);
  const wide = verticalView(cam, 2);
  check(Math.abs(Math.tan((wide.fov * Math.PI) / 360) - Math.tan(Math.PI / 6) / 2) < 1e-12, `course camera on a wide page: ${wide.fov} degrees vertical`);
  check(verticalView(cam, 0.5).fov === 60 && verticalView(cam, 1).fov === 60, 'course camera on a tall or square page: vertical');
  check(verticalView(resolveCamera(file, null, [0, 0, 0]), 2).fov === 30, "DESIGN.md's cameras stay vertical");
  check(verticalView({ ...cam, orthographic: true, orthoHeight: 4 }, 2).orthoHeight === 2, 'orthographic course camera: its size across the width');
  check(resolveCamera(course, parseHash('#eye=1,1,1&look=0,0,0'), [0, 0, 0]).spanLonger, 'eye and look keep the span');
  check(!resolveCamera(course, parseHash('#fov=50'), [0, 0, 0]).spanLonger, "the hash's fov is vertical");
}
finish();
