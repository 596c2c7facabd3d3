// Shared by the viewer page's tests (tests/viewer/*_test.mjs): the tools of the build folder, headless Chromium
// driven by playwright-core (installed by the build into BUILD/viewer/node_modules from viewer/package-lock.json),
// a PNG reader, and the silhouette comparison.
// Usage of every test: node tests/viewer/NAME_test.mjs BUILD_DIR SOURCE_DIR
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { inflateSync } from 'node:zlib';

export const build = resolve(process.argv[2] ?? 'build');
export const source = resolve(process.argv[3] ?? '.');
export const seed = process.env.VOX_SEED_DIR ?? join(source, 'data');
export const chromiumPath = process.env.VOX_CHROMIUM ?? '/usr/bin/chromium';
export const SKIP = 77;

let failures = 0;
export function check(ok, message) {
  if (ok) {
    console.log(`ok: ${message}`);
  } else {
    console.log(`FAIL: ${message}`);
    failures += 1;
  }
  return ok;
}
export function finish() {
  if (failures) console.log(`${failures} check(s) failed`);
  process.exit(failures ? 1 : 0);
}

export function requireFromBuild(name) {
  const pkg = join(build, 'viewer', 'package.json');
  if (!existsSync(pkg)) {
    console.log(`SKIP: ${pkg} missing (configured with VOX_VIEWER=OFF?)`);
    process.exit(SKIP);
  }
  return createRequire(pkg)(name);
}

export function tool(name, ...args) {
  return execFileSync(join(build, name), args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}

export function scratch(tag) {
  const dir = mkdtempSync(join(tmpdir(), `vox_viewer_${tag}_`));
  process.on('exit', () => rmSync(dir, { recursive: true, force: true }));
  return dir;
}

// The page's data elements as the page reads them ({text, encoding, bytes} of each <script
// type="application/x-vox-data">), for viewer/src/data.js layoutFromElements.
export function pageData(htmlPath) {
  const html = readFileSync(htmlPath, 'utf8');
  const re = /<script type="application\/x-vox-data"([^>]*)>([^<]*)<\/script>/g;
  return [...html.matchAll(re)].map((m) => ({
    text: m[2],
    encoding: /data-encoding="([^"]*)"/.exec(m[1])?.[1],
    bytes: /data-bytes="([^"]*)"/.exec(m[1])?.[1],
  }));
}

export async function launch() {
  if (!existsSync(chromiumPath)) {
    console.log(`SKIP: ${chromiumPath} not installed (scripts/install-deps.sh --clients installs chromium)`);
    process.exit(SKIP);
  }
  const { chromium } = requireFromBuild('playwright-core');
  // No background traffic (the machine's network is closed, and the page must not need it); playwright gives
  // every launch a fresh, empty profile of its own.
  return chromium.launch({
    executablePath: chromiumPath,
    args: [
      '--headless',
      '--no-sandbox',
      '--disable-gpu',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
      '--no-first-run',
      '--disable-quic',
    ],
  });
}

// Opens the page at `htmlPath` (with `hash`) in a new page of `size` [w, h] and waits for its first frame. Returns
// {page, errors (console errors and page errors), requests (every URL requested)}. query: '?name=value' for the
// page's options (?voxels=cubes).
export async function openPage(browser, htmlPath, { hash = '', query = '', size = [480, 360], timeout = 120000 } = {}) {
  const context = await browser.newContext({ viewport: { width: size[0], height: size[1] }, deviceScaleFactor: 1 });
  const page = await context.newPage();
  const errors = [];
  const requests = [];
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('request', (r) => requests.push(r.url()));
  const url = pathToFileURL(htmlPath).href + query + hash;
  await page.goto(url, { timeout });
  await page.waitForFunction(() => window.voxViewer && (window.voxViewer.ready || window.voxViewer.error), null, {
    timeout,
    polling: 100,
  });
  const error = await page.evaluate(() => window.voxViewer.error);
  if (error) errors.push(`page: ${error}`);
  return { page, context, errors, requests, url };
}

// Waits until the page has drawn what was last asked of it (frames counted by the page; two more frames).
export async function settle(page) {
  const n = await page.evaluate(() => window.voxViewer.frames);
  await page.evaluate(() => window.voxViewer.render());
  await page.waitForFunction((m) => window.voxViewer.frames > m, n, { polling: 50 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
}

// PNG (8-bit greyscale, RGB, or RGBA; not interlaced) -> {width, height, channels, data}.
export function readPng(buffer) {
  const sig = '89504e470d0a1a0a';
  if (buffer.subarray(0, 8).toString('hex') !== sig) throw new Error('not a PNG');
  let at = 8;
  let width = 0;
  let height = 0;
  let colorType = 0;
  const idat = [];
  while (at < buffer.length) {
    const length = buffer.readUInt32BE(at);
    const type = buffer.toString('latin1', at + 4, at + 8);
    const body = buffer.subarray(at + 8, at + 8 + length);
    if (type === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      if (body[8] !== 8 || body[12] !== 0) throw new Error('PNG: only 8-bit, non-interlaced images');
      colorType = body[9];
    } else if (type === 'IDAT') {
      idat.push(body);
    } else if (type === 'IEND') {
      break;
    }
    at += 12 + length;
  }
  const channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[colorType];
  if (!channels) throw new Error(`PNG: colour type ${colorType} not read here`);
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const data = new Uint8Array(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? data[y * stride + x - channels] : 0;
      const b = y > 0 ? data[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? data[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const pa = Math.abs(p - a);
        const pb = Math.abs(p - b);
        const pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      data[y * stride + x] = v & 255;
    }
  }
  return { width, height, channels, data };
}

// Which pixels differ from the background `bg` (three bytes) by more than `tolerance` in some channel.
export function coverage(image, bg, tolerance = 3) {
  const n = image.width * image.height;
  const mask = new Uint8Array(n);
  for (let p = 0; p < n; ++p) {
    for (let c = 0; c < 3; ++c) {
      const v = image.channels >= 3 ? image.data[p * image.channels + c] : image.data[p * image.channels];
      if (Math.abs(v - bg[c]) > tolerance) mask[p] = 1;
    }
  }
  return mask;
}

export function iou(a, b) {
  let both = 0;
  let either = 0;
  for (let p = 0; p < a.length; ++p) {
    both += a[p] & b[p];
    either += a[p] | b[p];
  }
  return { iou: either ? both / either : 1, both, either, a: a.reduce((s, x) => s + x, 0), b: b.reduce((s, x) => s + x, 0) };
}

export const hashOf = (cam) =>
  `#eye=${cam.eye.join(',')}&look=${cam.look.join(',')}&up=${(cam.up ?? [0, 1, 0]).join(',')}&fov=${cam.fov}`;

const sub = (a, b) => a.map((x, i) => x - b[i]);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => a.map((x) => x / Math.hypot(...a));
// The pointer position (CSS pixels) of world point p on a page of `size` [w, h] seen by perspective camera `cam`
// (hashOf's {eye, look, up, fov}, fov vertical): the inverse of vox-trace's primary ray (DESIGN.md).
export function projectPoint(cam, p, size) {
  const dir = unit(sub(cam.look, cam.eye));
  const right = unit(cross(dir, cam.up ?? [0, 1, 0]));
  const up = cross(right, dir);
  const d = sub(p, cam.eye);
  const t = Math.tan((cam.fov * Math.PI) / 360);
  const u = dot(d, right) / dot(d, dir);
  const v = dot(d, up) / dot(d, dir);
  return [(u / (t * (size[0] / size[1])) + 1) * 0.5 * size[0], (1 - v / t) * 0.5 * size[1]];
}

export function info(grid, ...flags) {
  return JSON.parse(tool('vox-info', grid, '--json', ...flags));
}
