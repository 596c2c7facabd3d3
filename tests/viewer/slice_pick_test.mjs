// The slice plane and the cell read-out, driven as a user drives them (the axis menu, the slider by the keyboard,
// clicks and pointer moves on the canvas):
//  - a filled 8^3 cube sliced at the middle shows half its voxels (counted by the page, 256 of 512) and half its
//    silhouette seen across the cut; the cut face shows the solid cells' grey;
//  - the bunny at 40x40x33 sliced on z shows exactly the cells of vox-info on the kept side, flipped the others;
//  - clicking a known voxel (found by projecting its face's centre with DESIGN.md's camera convention) shows its
//    index, its primitive count and first primitive ids as vox-info lists them; hovering shows a cell; a click in
//    the cut cube's middle shows a solid cell.
import { join } from 'node:path';

import {
  check, coverage, finish, hashOf, info, launch, openPage, projectPoint, readPng, scratch, settle, source, tool,
} from './lib.mjs';

const dir = scratch('slice');
const size = [400, 300];
const cube = join(dir, 'cube.vgrid');
tool('vox-voxelize', join(source, 'tests', 'data', 'unit_cube.obj'), '-o', cube, '--grid', '8', '8', '8', '--fill',
  '--quiet');
tool('vox-export', cube, '-o', `${cube}.html`, '--quiet');
const cubeInfo = info(cube, '--cells');
check(cubeInfo.occupied_cells === 296 && cubeInfo.solid_cells === 216, 'the filled cube has 296 + 216 voxels');

const project = (cam, p) => projectPoint(cam, p, size);

async function slice(page, axis, pos, flip = false) {
  await page.selectOption('#vox-slice-axis', String(axis));
  if (flip !== (await page.isChecked('#vox-slice-flip'))) await page.click('#vox-slice-flip');
  // The slider starts at the end that shows everything; the arrow keys move it one plane at a time.
  const start = Number(await page.inputValue('#vox-slice'));
  await page.focus('#vox-slice');
  for (let v = start; v !== pos; v += pos > v ? 1 : -1) await page.keyboard.press(pos > v ? 'ArrowRight' : 'ArrowLeft');
  check(Number(await page.inputValue('#vox-slice')) === pos, `slider at ${pos}`);
  return page.$eval('#vox-shown', (e) => [Number(e.dataset.shown), Number(e.dataset.total)]);
}

async function covered(page, bg) {
  await settle(page);
  return coverage(readPng(await page.screenshot({ type: 'png' })), bg).reduce((s, x) => s + x, 0);
}

const browser = await launch();
{
  // Seen from above (+y), across the cut on x.
  const cam = { eye: [0.5, 6, 0.5], look: [0.5, 0.5, 0.5], up: [0, 0, -1], fov: 20 };
  const { page, context, errors } = await openPage(browser, `${cube}.html`, { hash: hashOf(cam), size });
  await page.evaluate(() => window.voxViewer.setPanelHidden(false));
  await page.click('#vox-show-bounds');
  const bg = await page.evaluate(() => window.voxViewer.data.background.map((x) => Math.round(x * 255)));
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  const whole = await covered(page, bg);
  await page.evaluate(() => window.voxViewer.setPanelHidden(false));
  const [shown, total] = await slice(page, 0, 4);
  check(shown === 256 && total === 512, `slice x < 4 of the cube: ${shown} of ${total} voxels shown`);
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  const half = await covered(page, bg);
  check(Math.abs(half / whole - 0.5) < 0.05, `the silhouette halves too (${half} of ${whole} pixels)`);
  await page.evaluate(() => window.voxViewer.setPanelHidden(false));
  const [far] = await slice(page, 0, 4, true);
  check(far === 256, `the far side of x = 4: ${far} voxels`);
  const [none] = await slice(page, 0, 0, false);
  check(none === 0, `slice x < 0: nothing (${none})`);
  // The cut seen face on, from above (slice y < 4): the solid cells' grey (kSolidCellColor 153, lit 1.0 on faces
  // looking up) fills the middle; the background is 128.
  await slice(page, 1, 4, false);
  await page.evaluate(() => {
    window.location.hash = '#eye=0.5,4,0.5&look=0.5,0.5,0.5&up=0,0,-1&fov=20';
  });
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await settle(page);
  const shot = readPng(await page.screenshot({ type: 'png' }));
  const mid = ((size[1] >> 1) * size[0] + (size[0] >> 1)) * shot.channels;
  const rgb = [...shot.data.subarray(mid, mid + 3)];
  check(rgb.every((x) => Math.abs(x - 153) <= 2), `the cut shows solid cells (centre pixel ${rgb}, want ~153)`);
  // Clicking there: a solid cell of layer y = 3 (the kept layer at the cut).
  await page.mouse.click(size[0] / 2 + 0.5, size[1] / 2 + 0.5);
  const solid = await page.$eval('#vox-info', (e) => ({ ...e.dataset, text: e.textContent }));
  check(solid.solid === '1' && solid.ijk.split(',')[1] === '3', `the click in the cut finds a solid cell (${solid.text})`);
  check(errors.length === 0, `cube: no console error (${errors.join(' | ') || 'none'})`);

  // A known voxel of the top layer, clicked from above: cell (2, 7, 5) (y is up here).
  const top = { eye: [0.5, 4, 0.5], look: [0.5, 0.5, 0.5], up: [0, 0, -1], fov: 30 };
  await page.evaluate((h) => {
    window.location.hash = h;
  }, hashOf(top));
  await page.evaluate(() => window.voxViewer.setPanelHidden(false));
  await page.selectOption('#vox-slice-axis', '-1');
  await page.evaluate(() => window.voxViewer.setPanelHidden(true));
  await settle(page);
  const [x, y] = project(top, [(2 + 0.5) / 8, 1, (5 + 0.5) / 8]);
  await page.mouse.click(x, y);
  const got = await page.$eval('#vox-info', (e) => ({ ...e.dataset, text: e.textContent }));
  const key = [2, 7, 5];
  const want = cubeInfo.cells.find((c) => c.ijk.every((v, a) => v === key[a]));
  check(got.ijk === '2,7,5', `clicking the voxel at (2, 7, 5) shows it (${got.text})`);
  check(
    want && Number(got.count) === want.prims.length && got.ids === want.prims.slice(0, 4).join(','),
    `with its count and first ids as vox-info lists them (${want ? want.prims : 'missing'})`,
  );
  check(/^pinned cell \(2, 7, 5\): \d+ primitives?/.test(got.text), `the read-out says so in words (${got.text})`);
  // Hovering another voxel while one is pinned keeps the pinned one; a click on empty space unpins, then hover shows.
  const [hx, hy] = project(top, [(6 + 0.5) / 8, 1, (1 + 0.5) / 8]);
  await page.mouse.click(5, 5);
  await page.mouse.move(hx, hy);
  await page.waitForFunction(() => document.getElementById('vox-info').dataset.ijk === '6,7,1', null, {
    timeout: 10000,
    polling: 50,
  });
  check(true, 'hovering shows the cell under the pointer (6, 7, 1)');
  await context.close();
}

{
  // The bunny: the counts on each side of a z slice are vox-info's.
  const bunny = join(dir, 'bunny.vgrid');
  tool('vox-voxelize', join(source, 'scenes', 'scene5_07_bunny_mesh_1k.txt'), '-o', bunny, '--grid', '40', '40', '33',
    '--quiet');
  tool('vox-export', bunny, '-o', `${bunny}.html`, '--quiet');
  const cells = info(bunny, '--cells').cells;
  const { page, context, errors } = await openPage(browser, `${bunny}.html`, { size });
  const below = cells.filter((c) => c.ijk[2] < 16).length;
  const [shown, total] = await slice(page, 2, 16);
  check(total === cells.length && shown === below, `bunny z < 16: ${shown} shown, vox-info ${below} of ${cells.length}`);
  const [flipped] = await slice(page, 2, 16, true);
  check(flipped === cells.length - below, `bunny z >= 16: ${flipped} shown`);
  const [ys] = await slice(page, 1, 20, false);
  check(ys === cells.filter((c) => c.ijk[1] < 20).length, `bunny y < 20: ${ys} shown`);
  check(errors.length === 0, `bunny: no console error (${errors.join(' | ') || 'none'})`);
  await context.close();
}
await browser.close();
finish();
