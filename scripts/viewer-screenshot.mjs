// Makes the picture of the viewer page in docs/vox-export.md (docs/images/viewer_duck.png): the Duck (seed glTF) at --res 64 with
// its texture colours, sliced at x < 34, cell lines on, one cell pinned; headless Chromium as in tests/viewer/.
// Usage: node scripts/viewer-screenshot.mjs BUILD_DIR SOURCE_DIR
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';

import { launch, openPage, scratch, seed, settle, source, tool } from '../tests/viewer/lib.mjs';

const dir = scratch('screenshot');
const grid = join(dir, 'Duck.vgrid');
tool('vox-voxelize', join(seed, 'gltf', 'Duck', 'glTF', 'Duck.gltf'), '-o', grid, '--res', '64', '--quiet');
const html = join(dir, 'Duck.html');
tool('vox-export', grid, '-o', html, '--color', 'material', '--quiet');
const browser = await launch();
const hash = '#eye=1.9,1.9,2.6&look=0.15,0.8,-0.05&up=0,1,0&fov=35';
const { page, errors } = await openPage(browser, html, { hash, size: [900, 560] });
if (errors.length) throw new Error(errors.join(' | '));
await page.selectOption('#vox-slice-axis', '0');
await page.focus('#vox-slice');
for (let i = 0; i < 30; ++i) await page.keyboard.press('ArrowLeft');
await page.click('#vox-show-lines');
await settle(page);
await page.mouse.click(470, 430);
await settle(page);
writeFileSync(join(source, 'docs', 'images', 'viewer_duck.png'), await page.screenshot({ type: 'png' }));
console.log(await page.$eval('#vox-info', (e) => e.textContent));
await browser.close();
