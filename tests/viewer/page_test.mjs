// The viewer page opens from file:// in headless Chromium with no console error and no network request, for the
// grids that break viewers: empty, 1x1x1, 2048x3x1 (a long thin lattice), a grid with solid cells, a grid set
// (bricks); it shows the grid's facts, and its camera follows the hash both ways (set by the hash; the hash updated
// when the user drags).
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';

import { check, coverage, finish, info, launch, openPage, readPng, scratch, settle, source, tool } from './lib.mjs';

const dir = scratch('page');
const cases = [];

// An empty grid: a scene of one plane (no bounded primitive: an empty 1x1x1 grid).
writeFileSync(
  join(dir, 'plane.txt'),
  `OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Lights { numLights 1 DirectionalLight { direction 0 0 -1 color 1 1 1 } }
Background { color 0.2 0.3 0.4 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 PhongMaterial { diffuseColor 1 0 0 } }
Group { numObjects 1 MaterialIndex 0 Plane { normal 0 0 1 offset -1 } }
`,
);
tool('vox-voxelize', join(dir, 'plane.txt'), '-o', join(dir, 'empty.vgrid'), '--quiet');
cases.push({ name: 'empty', grid: 'empty.vgrid', occupied: 0 });

// One cell: the unit cube at 1x1x1.
const cube = join(source, 'tests', 'data', 'unit_cube.obj');
tool('vox-voxelize', cube, '-o', join(dir, 'one.vgrid'), '--grid', '1', '1', '1', '--quiet');
cases.push({ name: '1x1x1', grid: 'one.vgrid' });

// 2048 x 3 x 1: a long thin lattice (the cube's surface cells).
tool('vox-voxelize', cube, '-o', join(dir, 'long.vgrid'), '--grid', '2048', '3', '1', '--quiet');
cases.push({ name: '2048x3x1', grid: 'long.vgrid' });

// Solid cells (--fill) and a grid set of bricks.
const bunny = join(source, 'scenes', 'bunny_1k.obj');
tool('vox-voxelize', bunny, '-o', join(dir, 'filled.vgrid'), '--res', '24', '--fill', '--quiet');
cases.push({ name: 'filled', grid: 'filled.vgrid' });
tool('vox-voxelize', bunny, '-o', join(dir, 'set.vgrid'), '--res', '24', '--bricks', '2', '2', '2', '--quiet');
tool('vox-voxelize', bunny, '-o', join(dir, 'single.vgrid'), '--res', '24', '--quiet');
cases.push({ name: 'grid set', grid: 'set.vgrid', sameAs: 'single.vgrid' });

const browser = await launch();
for (const c of cases) {
  const grid = join(dir, c.grid);
  const html = join(dir, `${c.grid}.html`);
  tool('vox-export', grid, '-o', html, '--quiet');
  const facts = info(grid);
  const { page, context, errors, requests, url } = await openPage(browser, html);
  check(errors.length === 0, `${c.name}: no console error (${errors.join(' | ') || 'none'})`);
  const others = requests.filter((u) => u !== url && u !== url.split('#')[0]);
  check(others.length === 0, `${c.name}: no request but the page itself (${others.join(' ') || 'none'})`);
  const shown = await page.$eval('#vox-shown', (e) => ({ shown: Number(e.dataset.shown), total: Number(e.dataset.total) }));
  const voxels = facts.occupied_cells + (facts.solid_cells ?? 0);
  check(
    shown.total === voxels && shown.shown === voxels,
    `${c.name}: the page counts ${shown.shown} of ${shown.total} voxels, vox-info ${voxels}`,
  );
  const stats = await page.$eval('#vox-stats', (e) => e.textContent);
  check(stats.startsWith(`${facts.dims.join(' × ')} cells`), `${c.name}: shows the dims (${stats})`);
  if (c.sameAs) {
    // A set shows what the single grid shows: same cells, same surface.
    const single = join(dir, `${c.sameAs}.html`);
    tool('vox-export', join(dir, c.sameAs), '-o', single, '--quiet');
    const other = await openPage(browser, single);
    const a = await page.evaluate(() => [window.voxViewer.data.triangleCount, window.voxViewer.data.occupiedCount]);
    const b = await other.page.evaluate(() => [window.voxViewer.data.triangleCount, window.voxViewer.data.occupiedCount]);
    check(a[0] === b[0] && a[1] === b[1] && a[1] > 0, `${c.name}: same surface and cells as one grid (${a} / ${b})`);
    await other.context.close();
  }
  await context.close();
}

// Large surfaces first show the coarse stand-in, then the full surface (forced here on a small grid by ?lod=).
{
  const html = join(dir, 'filled.vgrid.html');
  const { page, context, errors } = await openPage(browser, html, { query: '?lod=2000' });
  const lod = await page.evaluate(() => ({ factor: window.voxViewer.lod.factor, faces: window.voxViewer.lod.faces }));
  const triangles = await page.evaluate(() => window.voxViewer.data.triangleCount);
  check(lod.factor >= 2 && 2 * lod.faces <= 2000, `a stand-in of blocks of ${lod.factor}^3: ${2 * lod.faces} triangles for ${triangles}`);
  await page.waitForFunction(() => window.voxViewer.timings.firstFullRender && !window.voxViewer.lod.coarse, null, {
    timeout: 30000,
    polling: 100,
  });
  check(true, 'then the full surface');
  check(errors.length === 0, `stand-in: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}

// The toggles: each layer drawn or not as its box says (pixels that differ from the background, panel hidden).
{
  const html = join(dir, 'filled.vgrid.html');
  const hash = '#eye=0.05,0.25,0.45&look=-0.02,0.1,0.01&up=0,1,0&fov=40';
  const { page, context, errors } = await openPage(browser, html, { hash, size: [320, 240] });
  const bg = await page.evaluate(() => window.voxViewer.data.background.map((x) => Math.round(x * 255)));
  const shot = async () => {
    await page.evaluate(() => window.voxViewer.setPanelHidden(true));
    await settle(page);
    const image = readPng(await page.screenshot({ type: 'png' }));
    await page.evaluate(() => window.voxViewer.setPanelHidden(false));
    return image;
  };
  const covered = (image) => coverage(image, bg).reduce((n, x) => n + x, 0);
  const differ = (a, b) => a.data.reduce((n, x, i) => n + (x !== b.data[i] ? 1 : 0), 0);
  const voxels = await shot();
  await page.click('#vox-show-lines');
  const lines = await shot();
  check(differ(voxels, lines) > 500, `cell lines drawn when on (${differ(voxels, lines)} bytes differ)`);
  await page.click('#vox-show-lines');
  await page.click('#vox-show-voxels');
  await page.click('#vox-show-bounds');
  const nothing = covered(await shot());
  check(nothing === 0, `voxels and bounds off: nothing drawn (${nothing} pixels)`);
  await page.click('#vox-show-triangles');
  const triangles = covered(await shot());
  check(triangles > 1000, `the scene's triangles on: ${triangles} pixels`);
  await page.click('#vox-show-triangles');
  await page.click('#vox-show-bounds');
  const bounds = covered(await shot());
  check(bounds > 100 && bounds < triangles, `the bounds' lines on: ${bounds} pixels`);
  check(errors.length === 0, `toggles: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}

// The camera: set by the hash (the page's camera is the hash's), kept in the hash when the user drags, and
// followed when the hash changes.
{
  const html = join(dir, 'filled.vgrid.html');
  const hash = '#eye=0.9,0.5,1.3&look=-0.02,0.1,0.01&up=0,1,0&fov=30';
  const { page, context, errors } = await openPage(browser, html, { hash, size: [400, 300] });
  const view = await page.evaluate(() => window.voxViewer.view());
  const near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) < 1e-9);
  check(
    near(view.eye, [0.9, 0.5, 1.3]) && near(view.look, [-0.02, 0.1, 0.01]) && view.fov === 30,
    `the hash sets the camera (${JSON.stringify(view)})`,
  );
  // On the canvas, right of the panel.
  await page.mouse.move(330, 150);
  await page.mouse.down();
  await page.mouse.move(390, 170, { steps: 5 });
  await page.mouse.up();
  // The hash is written a moment after the camera stops (then it holds the camera shown).
  const settled = await page
    .waitForFunction(
      () => {
        const m = /eye=([^&]+)/.exec(window.location.hash);
        const eye = window.voxViewer.view().eye;
        return m && m[1].split(',').every((x, i) => Math.abs(Number(x) - eye[i]) < 1e-6 * (1 + Math.abs(eye[i])));
      },
      null,
      { timeout: 10000, polling: 100 },
    )
    .then(() => true)
    .catch(() => false);
  check(settled, 'after the drag the hash holds the camera the page shows');
  const after = await page.evaluate(() => ({ hash: window.location.hash, view: window.voxViewer.view() }));
  const m = /^#eye=([^&]+)&look=([^&]+)&up=([^&]+)&fov=([^&]+)$/.exec(after.hash);
  check(m !== null, `dragging writes the camera into the hash (${after.hash})`);
  if (m) {
    const eye = m[1].split(',').map(Number);
    check(!near(eye, [0.9, 0.5, 1.3]), 'the eye in the hash moved with the drag');
  }
  // A new hash (a shared link pasted) moves the camera.
  await page.evaluate(() => {
    window.location.hash = '#eye=0,0,3&look=0,0,0&up=0,1,0&fov=50';
  });
  await page.waitForFunction(() => window.voxViewer.view().fov === 50, null, { timeout: 10000, polling: 100 });
  const moved = await page.evaluate(() => window.voxViewer.view());
  check(near(moved.eye, [0, 0, 3]) && near(moved.look, [0, 0, 0]), 'a changed hash moves the camera');
  // A bad hash is reported on the page, not thrown away silently.
  await page.evaluate(() => {
    window.location.hash = '#eye=1,2&look=0,0,0';
  });
  await page.waitForFunction(() => window.voxViewer.error, null, { timeout: 10000, polling: 100 });
  const bad = await page.evaluate(() => window.voxViewer.error);
  check(/eye needs three numbers/.test(bad), `a malformed hash is reported (${bad})`);
  check(errors.filter((e) => !/eye needs three numbers/.test(e)).length === 0, 'no other console error');
  await settle(page);
  await context.close();
}

await browser.close();
finish();
