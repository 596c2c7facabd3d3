// With the camera set through the hash, the page's screenshot covers the pixels that `vox-trace --mode voxels`
// covers with the same grid and camera (--eye --look-at --up --fov, DESIGN.md's camera convention): intersection over
// union of the covered pixels at least 0.95, for the course's bunny at 40x40x33 (three views, one close), the Duck
// with texture colours, and an empty grid (nothing covered in either). Without a hash the page takes the file's own
// camera, as vox-trace does without camera flags: a course orthographic and a perspective camera on pages twice as
// wide as high, whose size or angle spans the longer side. A pixel is covered when it differs from the
// scene's background. The page is shown as a user sees it, its panel hidden and the bounds' lines switched off.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

import { check, coverage, finish, hashOf, info, iou, launch, openPage, readPng, scratch, seed, settle, source, tool }
  from './lib.mjs';

const dir = scratch('silhouette');
const size = [320, 240];
const cases = [];

const frame = (facts) => {
  const lo = facts.bounds.min;
  const hi = facts.bounds.max;
  const c = lo.map((x, a) => 0.5 * (x + hi[a]));
  const r = 0.5 * Math.hypot(...hi.map((x, a) => x - lo[a]));
  return { c, r };
};
const at = (c, r, d) => c.map((x, a) => +(x + r * d[a]).toPrecision(10));

// The course's bunny.
tool('vox-voxelize', join(source, 'scenes', 'scene5_07_bunny_mesh_1k.txt'), '-o', join(dir, 'bunny.vgrid'),
  '--grid', '40', '40', '33', '--quiet');
{
  const { c, r } = frame(info(join(dir, 'bunny.vgrid')));
  cases.push({ name: 'bunny, oblique', grid: 'bunny.vgrid', cam: { eye: at(c, r, [1.4, 0.9, 2.4]), look: c, fov: 35 } });
  // A look point away from the grid's centre (the page once turned to the centre whatever the hash said).
  cases.push({
    name: 'bunny, looking past its centre',
    grid: 'bunny.vgrid',
    cam: { eye: at(c, r, [0.8, 1.0, 1.5]), look: at(c, r, [0.1, -0.6, 0]), fov: 35 },
  });
  cases.push({
    name: 'bunny, from above (up along z)',
    grid: 'bunny.vgrid',
    cam: { eye: at(c, r, [0.05, 3, 0.1]), look: c, up: [0, 0, -1], fov: 40 },
  });
  cases.push({ name: 'bunny, close', grid: 'bunny.vgrid', cam: { eye: at(c, r, [0.3, 0.2, 1.15]), look: c, fov: 70 } });
}

// The Duck, with texture colours.
const duck = join(seed, 'gltf', 'Duck', 'glTF', 'Duck.gltf');
tool('vox-voxelize', duck, '-o', join(dir, 'duck.vgrid'), '--res', '48', '--quiet');
{
  const { c, r } = frame(info(join(dir, 'duck.vgrid')));
  cases.push({
    name: 'Duck (material colours)',
    grid: 'duck.vgrid',
    color: 'material',
    cam: { eye: at(c, r, [-1.6, 0.8, 1.7]), look: c, fov: 40 },
  });
}

// A filled cube seen from near one corner, looking away from it: the near plane must keep the corner (the page once
// put it at the box's nearest distance, which clipped corners off the view's axis).
tool('vox-voxelize', join(source, 'tests', 'data', 'unit_cube.obj'), '-o', join(dir, 'cube.vgrid'), '--grid', '8', '8',
  '8', '--fill', '--quiet');
cases.push({ name: 'filled cube, near a corner', grid: 'cube.vgrid', cam: { eye: [1.35, 1.3, 1.4], look: [0.1, 0.6, 0.3], fov: 60 } });

// An empty grid: the bunny outside user-given bounds.
tool('vox-voxelize', join(source, 'scenes', 'bunny_1k.obj'), '-o', join(dir, 'empty.vgrid'), '--bounds', '5', '5',
  '5', '6', '6', '6', '--grid', '4', '4', '4', '--quiet');
cases.push({ name: 'empty grid', grid: 'empty.vgrid', cam: { eye: [5.5, 5.5, 8], look: [5.5, 5.5, 5.5], fov: 45 }, empty: true });

// The course's own cameras on wide pages.
tool('vox-voxelize', join(source, 'scenes', 'scene5_02_spheres.txt'), '-o', join(dir, 'spheres.vgrid'), '--res', '40',
  '--quiet');
cases.push({ name: 'course orthographic camera, 400x200', grid: 'spheres.vgrid', fileCamera: true, size: [400, 200] });
cases.push({ name: 'course perspective camera, 400x200', grid: 'bunny.vgrid', fileCamera: true, size: [400, 200] });

const browser = await launch();
for (const c of cases) {
  const grid = join(dir, c.grid);
  const shape = c.size ?? size;
  const html = join(dir, `${c.grid}.${c.color ?? 'count'}.html`);
  tool('vox-export', grid, '-o', html, '--color', c.color ?? 'count', '--quiet');
  const traced = join(dir, `${c.grid}.png`);
  const camera = c.fileCamera
    ? []
    : ['--eye', ...c.cam.eye.map(String), '--look-at', ...c.cam.look.map(String), '--up',
      ...(c.cam.up ?? [0, 1, 0]).map(String), '--fov', String(c.cam.fov)];
  tool('vox-trace', grid, '-o', traced, '--mode', 'voxels', '--size', String(shape[0]), String(shape[1]), ...camera,
    '--quiet');

  const hash = c.fileCamera ? undefined : hashOf(c.cam);
  const { page, context, errors } = await openPage(browser, html, { hash, size: shape });
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await page.evaluate(() => document.getElementById('vox-show-bounds').click());
  await settle(page);
  const shot = readPng(await page.screenshot({ type: 'png' }));
  const bg = await page.evaluate(() => window.voxViewer.data.background.map((x) => Math.round(Math.min(Math.max(x, 0), 1) * 255)));
  const mine = coverage(shot, bg);
  const theirs = coverage(readPng(readFileSync(traced)), bg);
  const r = iou(mine, theirs);
  check(errors.length === 0, `${c.name}: no console error (${errors.join(' | ') || 'none'})`);
  if (c.empty) {
    check(r.a === 0 && r.b === 0, `${c.name}: nothing covered (page ${r.a}, vox-trace ${r.b} pixels)`);
  } else {
    const pixels = shape[0] * shape[1];
    check(r.b > 0.02 * pixels, `${c.name}: vox-trace covers ${r.b} pixels (the view shows the grid)`);
    check(r.iou >= 0.95, `${c.name}: IoU ${r.iou.toFixed(4)} >= 0.95 (page ${r.a}, vox-trace ${r.b}, both ${r.both})`);
  }
  await context.close();
}
await browser.close();
finish();
