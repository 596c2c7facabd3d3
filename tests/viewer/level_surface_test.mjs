// The level surface d = 0 on the viewer page (issue 47): a grid with distances (--sdf) gives a page holding the
// surface `vox-export --surface` writes (same vertex and triangle counts) and a "surface" toggle; switched on, with
// the voxels switched off, the frame draws exactly its triangles, where the voxels are drawn from the same camera (at
// least 97% of its pixels are the voxels', which reach up to a cell beyond it: the bunny at 24 cells); switched off
// again, nothing but the background. A grid without distances has no surface and no toggle. No console error, no
// request but the page (it stays self-contained).
import { spawnSync } from 'node:child_process';
import { join } from 'node:path';

import { build, check, coverage, finish, hashOf, info, iou, launch, openPage, readPng, scratch, seed, settle, tool }
  from './lib.mjs';

const dir = scratch('level');
const bunny = join(seed, '6837', 'scenes', 'bunny_1k.obj');
tool('vox-voxelize', bunny, '-o', join(dir, 'sdf.vgrid'), '--res', '24', '--sdf', '--quiet');
tool('vox-voxelize', bunny, '-o', join(dir, 'plain.vgrid'), '--res', '24', '--quiet');
// vox-export --surface --stats: its counts on stderr.
const run = spawnSync(join(build, 'vox-export'), [join(dir, 'sdf.vgrid'), '-o', join(dir, 's.ply'), '--surface',
  '--stats', '--quiet'], { encoding: 'utf8' });
const stat = (name) => Number(new RegExp(`^${name}: (\\d+)$`, 'm').exec(run.stderr)?.[1]);
const expected = { vertices: stat('vertices'), triangles: stat('faces') };
check(run.status === 0 && expected.triangles > 0, `vox-export --surface: ${expected.triangles} triangles`);
tool('vox-export', join(dir, 'sdf.vgrid'), '-o', join(dir, 'sdf.html'), '--quiet');
tool('vox-export', join(dir, 'plain.vgrid'), '-o', join(dir, 'plain.html'), '--quiet');

const facts = info(join(dir, 'sdf.vgrid'));
const lo = facts.bounds.min;
const hi = facts.bounds.max;
const c = lo.map((x, a) => 0.5 * (x + hi[a]));
const r = 0.5 * Math.hypot(...hi.map((x, a) => x - lo[a]));
const cam = { eye: c.map((x, a) => +(x + r * [1.4, 0.9, 2.4][a]).toPrecision(10)), look: c, fov: 35 };

const browser = await launch();
{
  const { page, context, errors, requests, url } = await openPage(browser, join(dir, 'sdf.html'), {
    hash: hashOf(cam),
    size: [320, 240],
  });
  const got = await page.evaluate(() => ({
    has: window.voxViewer.data.hasLevelSurface,
    vertices: window.voxViewer.data.levelVertexCount,
    triangles: window.voxViewer.data.levelTriangleCount,
    toggle: !!document.getElementById('vox-show-level'),
  }));
  check(
    got.has && got.vertices === expected.vertices && got.triangles === expected.triangles,
    `the page holds the surface of --surface (${got.vertices} / ${expected.vertices} vertices, ` +
      `${got.triangles} / ${expected.triangles} triangles)`,
  );
  check(got.toggle, 'a grid with distances has the surface toggle');
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await page.evaluate(() => document.getElementById('vox-show-bounds').click());
  const bg = await page.evaluate(() =>
    window.voxViewer.data.background.map((x) => Math.round(Math.min(Math.max(x, 0), 1) * 255)));
  const shot = async () => {
    await settle(page);
    return coverage(readPng(await page.screenshot({ type: 'png' })), bg);
  };
  const voxels = await shot();
  const voxelTriangles = await page.evaluate(() => window.voxViewer.drawnTriangles);
  // The surface alone.
  await page.evaluate(() => document.getElementById('vox-show-voxels').click());
  await page.evaluate(() => document.getElementById('vox-show-level').click());
  const level = await shot();
  const drawn = await page.evaluate(() => window.voxViewer.drawnTriangles);
  check(drawn === expected.triangles, `the surface alone: the frame draws ${drawn} triangles, the surface has ${expected.triangles}`);
  const overlap = iou(level, voxels);
  check(overlap.a > 0.02 * 320 * 240, `the surface covers ${overlap.a} pixels`);
  // The surface lies inside the voxels (cells the mesh crosses), which reach up to a cell beyond it: its pixels
  // are the voxels' pixels, and cover most of them.
  const inside = overlap.both / overlap.a;
  check(inside >= 0.97 && overlap.iou >= 0.6, `the surface is drawn where the voxels are: ${(100 * inside).toFixed(1)}% ` +
    `of its pixels >= 97%, IoU ${overlap.iou.toFixed(3)} >= 0.6 (surface ${overlap.a}, voxels ${overlap.b}, voxels ` +
    `drew ${voxelTriangles} triangles)`);
  // Both off: the background only.
  await page.evaluate(() => document.getElementById('vox-show-level').click());
  const none = await shot();
  const left = none.reduce((s, x) => s + x, 0);
  check(left === 0, `surface and voxels off: ${left} pixels covered`);
  check(errors.length === 0, `no console error (${errors.join(' | ') || 'none'})`);
  const others = requests.filter((u) => u !== url && u !== url.split('#')[0]);
  check(others.length === 0, `no request but the page itself (${others.join(' ') || 'none'})`);
  await context.close();
}
{
  const { page, context, errors } = await openPage(browser, join(dir, 'plain.html'));
  const got = await page.evaluate(() => ({
    has: window.voxViewer.data.hasLevelSurface,
    toggle: !!document.getElementById('vox-show-level'),
  }));
  check(!got.has && !got.toggle, `a grid without distances: no surface (${got.has}), no toggle (${got.toggle})`);
  check(errors.length === 0, `no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}
await browser.close();
finish();
