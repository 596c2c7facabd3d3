// The viewer page on large grids (issue 25): the 69k-triangle Stanford bunny (seed meshes) voxelized at --res N,
// exported as a page and as the binary --faces merged PLY; the page opened from file:// in headless Chromium with
// software GL (SwiftShader: --disable-gpu), timed to its first frame; then the time of a frame while the camera
// turns (a drag), the merged surface against one instanced cube per voxel (the page's ?voxels=cubes).
// Usage: node bench/viewer_bench.mjs BUILD_DIR SOURCE_DIR [N ...]   (default N: 128 256 512 1024)
// Prints one line per measurement on stderr and a Markdown table on stdout. The machine's load average is printed
// with it: software GL shares the CPU with everything else.
import { execFileSync, spawnSync } from 'node:child_process';
import { statSync } from 'node:fs';
import { loadavg } from 'node:os';
import { join } from 'node:path';

import { build, launch, openPage, scratch, seed } from '../tests/viewer/lib.mjs';

const sizes = process.argv.slice(4).map(Number);
const resolutions = sizes.length ? sizes : [128, 256, 512, 1024];
const mesh = join(seed, 'meshes', 'derived', 'stanford_bunny_69k.obj');
const dir = scratch('bench');
const viewport = [1280, 800];
const log = (...a) => console.error(...a);
const seconds = (t0) => (performance.now() - t0) / 1000;
const mb = (bytes) => (bytes / 1e6).toFixed(1);

function run(tool, ...args) {
  return execFileSync(join(build, tool), args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}
function statsOf(text) {
  return Object.fromEntries(
    text
      .split('\n')
      .map((l) => l.split(': '))
      .filter((p) => p.length === 2),
  );
}

// Opens the page, waits for its first frame and for the GPU to have finished it (a one-pixel read-back), then
// times three frames of a turning camera.
// Large grids first show a coarse stand-in (viewer/src/lod.js): then "first frame" is that one, "full" the first
// frame of the full surface, and the frame while turning is the stand-in's (the full surface's is timed too).
async function measure(html, query = '') {
  const browser = await launch();
  const t0 = performance.now();
  const { page, errors } = await openPage(browser, html, { query, size: viewport, timeout: 900000 });
  const ready = seconds(t0);
  await page.waitForFunction(() => window.voxViewer.timings.firstFullRender, null, { timeout: 900000, polling: 100 });
  const t = await page.evaluate(() => {
    const gl = document.getElementById('vox-canvas').getContext('webgl2');
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    return { ...window.voxViewer.timings, fullDrawn: performance.now() };
  });
  const lod = await page.evaluate(() => (window.voxViewer.lod.mesh ? { factor: window.voxViewer.lod.factor, faces: window.voxViewer.lod.faces } : null));
  const frameMs = await page.evaluate(() => window.voxViewer.timeFrames(3, false));
  const coarseMs = lod ? await page.evaluate(() => window.voxViewer.timeFrames(3, true)) : null;
  await browser.close();
  if (errors.length) throw new Error(`${html}: ${errors.join(' | ')}`);
  return { ready, t, frameMs, coarseMs, lod };
}

const rows = [];
for (const res of resolutions) {
  const grid = join(dir, `bunny${res}.vgrid`);
  let t0 = performance.now();
  run('vox-voxelize', mesh, '-o', grid, '--res', String(res), '--quiet');
  log(`res ${res}: voxelized in ${seconds(t0).toFixed(1)} s`);
  const html = join(dir, `bunny${res}.html`);
  t0 = performance.now();
  const exported = spawnSync(join(build, 'vox-export'), [grid, '-o', html, '--stats', '--quiet'], { encoding: 'utf8' });
  if (exported.status !== 0) throw new Error(`vox-export: ${exported.stderr}`);
  const exportSeconds = seconds(t0);
  const stats = statsOf(exported.stderr);
  const ply = join(dir, `bunny${res}.ply`);
  run('vox-export', grid, '-o', ply, '--faces', 'merged', '--quiet');
  const pageBytes = statSync(html).size;
  const plyBytes = statSync(ply).size;
  const info = JSON.parse(run('vox-info', grid, '--json'));
  log(`res ${res}: page ${mb(pageBytes)} MB (written in ${exportSeconds.toFixed(1)} s), merged PLY ${mb(plyBytes)} MB`);
  const surface = await measure(html);
  log(`res ${res}: merged surface ${JSON.stringify(surface)}`);
  // Instanced cubes: one per voxel (skipped above 512: tens of millions of triangles).
  const cubes = res <= 512 ? await measure(html, '?voxels=cubes') : null;
  if (cubes) log(`res ${res}: instanced cubes ${JSON.stringify(cubes)}`);
  rows.push({ res, info, triangles: Number(stats.surface_triangles), pageBytes, plyBytes, surface, cubes, load: loadavg()[0] });
}

console.log(`Viewer page, Stanford bunny (69,451 triangles), headless Chromium ${viewport.join('x')}, SwiftShader:`);
console.log('');
console.log(
  '| --res | occupied cells | surface triangles | page MB | merged PLY MB | page / PLY | first frame s | ' +
    'full surface drawn s | frame, full surface s | frame while turning s | instanced cubes: first frame s, frame s | load avg |',
);
console.log('|---|---|---|---|---|---|---|---|---|---|---|---|');
for (const r of rows) {
  const f = (ms) => (ms / 1000).toFixed(2);
  const cubes = r.cubes ? `${f(r.cubes.t.fullDrawn)}, ${f(r.cubes.frameMs)}` : 'not run';
  const turning = r.surface.lod
    ? `${f(r.surface.coarseMs)} (blocks of ${r.surface.lod.factor}^3, ${(2 * r.surface.lod.faces).toLocaleString('en-US')} triangles)`
    : f(r.surface.frameMs);
  console.log(
    `| ${r.res} | ${r.info.occupied_cells.toLocaleString('en-US')} | ${r.triangles.toLocaleString('en-US')} | ` +
      `${mb(r.pageBytes)} | ${mb(r.plyBytes)} | ${(r.pageBytes / r.plyBytes).toFixed(2)} | ${f(r.surface.t.firstFrame)} | ` +
      `${f(r.surface.t.fullDrawn)} | ${f(r.surface.frameMs)} | ${turning} | ${cubes} | ${r.load.toFixed(1)} |`,
  );
}
