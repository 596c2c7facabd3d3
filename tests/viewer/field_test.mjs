// The slice plane's fields (issue 38): signed distances and volume fractions, as a user sees them.
//  - The unit cube at 13^3 with --sdf, its bounds chosen so that cell centres lie on the cube's faces: sliced on z
//    and seen face on, the plane shows a cell outside the cube reddish, one inside bluish and one whose centre is on
//    the surface white (the map of docs/viewer-format.md, to a few levels); hovering each shows the signed distance
//    of the .npz (numpy, from vox-export) rounded to float32, exactly; the 'voxel colours' choice removes the plane's
//    colours.
//  - The bunny with --sdf --fraction, the plane switched to fractions in the panel: every voxel of the sliced layer
//    shows a grey level of its fraction (to a few levels, so ordered like the fractions); hovering shows the
//    fraction of the .npz, and the distance too.
//  - A grid without them: the page's data is byte for byte the --sdf page's without the field's arrays, header
//    fields and flags, and the page offers no field.
import { execFileSync } from 'node:child_process';
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

import {
  SKIP, check, finish, hashOf, launch, openPage, pageData, projectPoint, readPng, scratch, settle, source, tool,
} from './lib.mjs';

const viewerSrc = (name) => pathToFileURL(join(source, 'viewer', 'src', name)).href;
const { decodeViewerData, layoutFromElements, HEADER_BYTES } = await import(viewerSrc('data.js'));

// Debian's numpy is the system Python's (as tests/cli/sdf_cli.sh reads the .npz).
const python = process.env.VOX_PYTHON3 ?? '/usr/bin/python3';
try {
  execFileSync(python, ['-c', 'import numpy'], { stdio: 'ignore' });
} catch {
  console.log(`SKIP: ${python} has no numpy (scripts/install-deps.sh --clients installs python3-numpy)`);
  process.exit(SKIP);
}
// Values of array `name` of an .npz at cells [[i, j, k], ...], as numpy reads them (float64, NaN as null).
function npzAt(npz, name, cells) {
  const script = `import json, sys, numpy as np
a = np.load(sys.argv[1])[sys.argv[2]]
print(json.dumps([None if np.isnan(a[i, j, k]) else float(a[i, j, k]) for i, j, k in json.loads(sys.argv[3])]))`;
  return JSON.parse(execFileSync(python, ['-c', script, npz, name, JSON.stringify(cells)], { encoding: 'utf8' }));
}

const dir = scratch('field');
const size = [480, 360];

// The pixel (sRGB bytes) of a screenshot at CSS position [x, y].
function pixel(shot, [x, y]) {
  const at = (Math.floor(y) * shot.width + Math.floor(x)) * shot.channels;
  return [...shot.data.subarray(at, at + 3)];
}
// What the read-out says of the cell under the pointer at [x, y] (hovered, nothing pinned).
async function hover(page, [x, y]) {
  const before = await page.$eval('#vox-info', (e) => e.textContent);
  await page.mouse.move(x, y);
  const changed = (t) => document.getElementById('vox-info').textContent !== t;
  await page.waitForFunction(changed, before, { timeout: 5000, polling: 50 }).catch(() => {});
  return page.$eval('#vox-info', (e) => ({ ...e.dataset, text: e.textContent }));
}
// Seen face on from above the plane z = `planeZ` (world), looking down -z at the middle of the grid's x and y.
const topCamera = (mid, planeZ, height) => ({ eye: [mid[0], mid[1], planeZ + height], look: [mid[0], mid[1], planeZ],
  up: [0, 1, 0], fov: 30 });

const browser = await launch();
const cube = join(dir, 'cube.vgrid');
{
  // Cells of 0.125 from -0.3125: cell i's centre is at -0.25 + 0.125 i, so i = 2 and 10 lie on the cube's faces.
  tool('vox-voxelize', join(source, 'tests', 'data', 'unit_cube.obj'), '-o', cube, '--grid', '13', '13', '13',
    '--bounds', '-0.3125', '-0.3125', '-0.3125', '1.3125', '1.3125', '1.3125', '--sdf', '--quiet');
  tool('vox-export', cube, '-o', `${cube}.html`, '--quiet');
  tool('vox-export', cube, '-o', `${cube}.npz`, '--quiet');
  const lattice = (i) => -0.3125 + 0.125 * i;
  const centre = (i) => lattice(i) + 0.0625;
  // Slice z < 7: the kept layer is k = 6 (centre z 0.5), the plane at z = lattice(7).
  const planeZ = lattice(7);
  const cam = topCamera([0.5, 0.5], planeZ, 4);
  const { page, context, errors } = await openPage(browser, `${cube}.html`, { hash: hashOf(cam), size });
  check((await page.$eval('#vox-slice-field', (e) => e.value)) === 'distance', 'the plane shows distances at first');
  await page.selectOption('#vox-slice-axis', '2');
  await page.focus('#vox-slice');
  for (let v = 13; v > 7; --v) await page.keyboard.press('ArrowLeft');
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await settle(page);
  const fieldCells = await page.evaluate(() => window.voxViewer.fieldCells);
  const shot = readPng(await page.screenshot({ type: 'png' }));
  // Row j = 6 (y centre 0.5) of layer 6: i = 0, 1 outside, 2 on the face x = 0, 3, 4 inside.
  const probe = [0, 1, 2, 3, 4].map((i) => [i, 6, 6]);
  const want = npzAt(`${cube}.npz`, 'sdf', probe);
  check(want.join() === '0.25,0.125,0,-0.125,-0.25', `the .npz's distances along the row: ${want}`);
  check(fieldCells > 0, `the plane colours ${fieldCells} band cells`);
  // The map of docs/viewer-format.md: from white at 0 to (180, 4, 38) at +limit and (59, 76, 192) at -limit, the
  // limit being the band's 3 cells of 0.125.
  const mapColor = (v) => {
    const t = Math.min(Math.abs(v) / 0.375, 1);
    return (v < 0 ? [59, 76, 192] : [180, 4, 38]).map((e) => 255 + (e - 255) * t);
  };
  for (const [n, ijk] of probe.entries()) {
    const at = projectPoint(cam, [centre(ijk[0]), centre(ijk[1]), planeZ], size);
    const rgb = pixel(shot, at);
    const v = want[n];
    const kind = v > 0 ? 'outside: reddish' : v < 0 ? 'inside: bluish' : 'on the surface: white';
    const looks = v > 0 ? rgb[0] > rgb[2] + 30 : v < 0 ? rgb[2] > rgb[0] + 30 : rgb.every((x) => x >= 250);
    check(looks, `cell (${ijk}) ${kind} (${rgb})`);
    const map = mapColor(v);
    check(rgb.every((x, c) => Math.abs(x - map[c]) <= 3), `cell (${ijk}) in the map's colour (${rgb}, map ${map})`);
    const got = await hover(page, at);
    check(got.ijk === ijk.join(), `hovering (${ijk}) shows it (${got.text})`);
    check(
      got.distance !== undefined && Number(got.distance) === Math.fround(v),
      `with its signed distance, the .npz's as float32 (${got.distance}, .npz ${v})`,
    );
    check(got.text.includes(`signed distance ${v}`), `in words (${got.text})`);
  }
  // The cell on the face is a voxel: its primitives are still shown beside its distance.
  const face = await hover(page, projectPoint(cam, [centre(2), centre(6), planeZ], size));
  check(/primitives?/.test(face.text) && Number(face.count) > 0, `the voxel's primitives too (${face.text})`);
  // Back to the voxels' colours: no field on the plane, and the empty cell outside the cube is not drawn.
  await page.evaluate(() => window.voxViewer.setPanelHidden(false));
  await page.selectOption('#vox-slice-field', 'voxels');
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await settle(page);
  const plain = readPng(await page.screenshot({ type: 'png' }));
  const bg = await page.evaluate(() => window.voxViewer.data.background.map((x) => Math.round(x * 255)));
  const outside = pixel(plain, projectPoint(cam, [centre(0), centre(6), planeZ], size));
  check(
    (await page.evaluate(() => window.voxViewer.fieldCells)) === 0 && outside.every((x, c) => Math.abs(x - bg[c]) <= 2),
    `'voxel colours': the plane shows no field (outside pixel ${outside}, background ${bg})`,
  );
  check(errors.length === 0, `cube: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}

{
  // The bunny with distances and fractions (and its fill's solid cells, fraction 1), sliced on z through its middle.
  const bunny = join(dir, 'bunny.vgrid');
  tool('vox-voxelize', join(source, 'scenes', 'bunny_1k.obj'), '-o', bunny, '--res', '20', '--sdf', '--fraction',
    '--quiet');
  tool('vox-export', bunny, '-o', `${bunny}.html`, '--quiet');
  tool('vox-export', bunny, '-o', `${bunny}.npz`, '--quiet');
  const d = decodeViewerData(await layoutFromElements(pageData(`${bunny}.html`)));
  const boundary = (a, i) => d.lo[a] + ((d.hi[a] - d.lo[a]) * i) / d.dims[a];
  const mid = (a, i) => 0.5 * (boundary(a, i) + boundary(a, i + 1));
  const pos = Math.floor(d.dims[2] / 2);
  const planeZ = boundary(2, pos);
  const extent = Math.max(d.hi[0] - d.lo[0], d.hi[1] - d.lo[1]);
  const cam = topCamera([mid(0, d.dims[0] / 2 - 0.5), mid(1, d.dims[1] / 2 - 0.5)], planeZ, (1.3 * extent) / 0.5359);
  const { page, context, errors } = await openPage(browser, `${bunny}.html`, { hash: hashOf(cam), size });
  check((await page.$eval('#vox-slice-field', (e) => e.value)) === 'distance', 'with both, distances come first');
  await page.selectOption('#vox-slice-field', 'fraction');
  check((await page.$eval('#vox-legend-range', (e) => e.textContent)) === '0 … 1', 'the scale says 0 to 1');
  await page.evaluate((p) => window.voxViewer.setSlice(2, p, true), pos);
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await settle(page);
  const shot = readPng(await page.screenshot({ type: 'png' }));
  // The kept layer's cells, and their fractions and voxels from the .npz.
  const layer = [];
  for (let i = 0; i < d.dims[0]; ++i) for (let j = 0; j < d.dims[1]; ++j) layer.push([i, j, pos - 1]);
  const fraction = npzAt(`${bunny}.npz`, 'fraction', layer);
  const occupancy = npzAt(`${bunny}.npz`, 'occupancy', layer);
  const solid = npzAt(`${bunny}.npz`, 'solid', layer);
  const shown = [];
  let worst = 0;
  let notGrey = 0;
  layer.forEach((ijk, n) => {
    if (!occupancy[n] && !solid[n]) return;
    const rgb = pixel(shot, projectPoint(cam, [mid(0, ijk[0]), mid(1, ijk[1]), planeZ], size));
    if (Math.max(...rgb) - Math.min(...rgb) > 2) ++notGrey;
    worst = Math.max(worst, Math.abs(rgb[0] - 255 * fraction[n]));
    shown.push({ ijk, f: fraction[n], grey: rgb[0] });
  });
  const partial = shown.filter((s) => s.f > 0 && s.f < 1).length;
  check(shown.length > 50 && partial > 20, `the layer holds ${shown.length} voxels, ${partial} partly inside`);
  check(notGrey === 0, `every voxel of the plane is grey (${notGrey} are not)`);
  check(worst <= 3, `grey level = 255 x fraction to ${worst.toFixed(2)} levels`);
  // Ordered like the fractions: a cell with a larger fraction (by more than 2 levels) is never darker.
  let disorder = 0;
  for (const a of shown) {
    for (const b of shown) if (a.f > b.f + 2 / 255 && a.grey < b.grey) ++disorder;
  }
  check(disorder === 0, `grey levels ordered like the fractions (${disorder} pairs out of order)`);
  // The read-out of a cell partly inside: the .npz's fraction as float32.
  const some = shown.filter((s) => s.f > 0.2 && s.f < 0.8).slice(0, 3);
  for (const s of some) {
    const got = await hover(page, projectPoint(cam, [mid(0, s.ijk[0]), mid(1, s.ijk[1]), planeZ], size));
    check(
      got.ijk === s.ijk.join() && Number(got.fraction) === Math.fround(s.f),
      `hovering (${s.ijk}) shows its fraction ${got.fraction} (.npz ${s.f}; ${got.text})`,
    );
    check(got.distance !== '' && got.text.includes(' · signed distance '), 'and its distance (in the band)');
  }
  check(errors.length === 0, `bunny: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}

{
  // The same cube without distances (the same file name, so the same title): the page's data is the --sdf page's
  // without the fields (its flag bits 8 to 10, header bytes 240-255 and the arrays after the spheres: the band's
  // and the level surface's), and the page offers no field.
  const plain = join(dir, 'plain', 'cube.vgrid');
  mkdirSync(join(dir, 'plain'));
  tool('vox-voxelize', join(source, 'tests', 'data', 'unit_cube.obj'), '-o', plain, '--grid', '13', '13', '13',
    '--bounds', '-0.3125', '-0.3125', '-0.3125', '1.3125', '1.3125', '1.3125', '--quiet');
  tool('vox-export', plain, '-o', `${plain}.html`, '--quiet');
  const before = await layoutFromElements(pageData(`${plain}.html`));
  const withSdf = (await layoutFromElements(pageData(`${cube}.html`))).slice();
  const flags = new DataView(withSdf.buffer).getUint32(12, true);
  check((flags & 0x700) === 0x500, 'the --sdf page sets flag bits 8 and 10 (distances and their surface) only');
  new DataView(withSdf.buffer).setUint32(12, flags & ~0x700, true);
  withSdf.fill(0, HEADER_BYTES - 16, HEADER_BYTES);
  const prefix = withSdf.subarray(0, before.length);
  check(
    withSdf.length > before.length && prefix.every((x, n) => x === before[n]),
    `the page without distances is the --sdf page's data without them (${before.length} of ${withSdf.length} bytes)`,
  );
  const d = decodeViewerData(before);
  check(!d.hasDistances && !d.hasFractions && d.distances === null, 'and reads as having no fields');
  const { page, context, errors } = await openPage(browser, `${plain}.html`, { size });
  check((await page.$('#vox-slice-field')) === null, 'its panel offers no field');
  await page.evaluate(() => window.voxViewer.setSlice(2, 7, true));
  check((await page.evaluate(() => window.voxViewer.fieldCells)) === 0, 'its slice plane draws no field');
  check(errors.length === 0, `plain cube: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}
await browser.close();
finish();
