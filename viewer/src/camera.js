// The camera in the URL's hash, `#eye=x,y,z&look=x,y,z&up=x,y,z&fov=deg` (DESIGN.md "Viewer page"), and the camera
// it gives together with the grid file's, resolved exactly as vox-trace resolves --eye/--look-at/--up/--fov
// (tools/trace/main.cpp resolveCamera), so that the same numbers give the same picture in both.
// World coordinates throughout (not relative to the grid's centre).

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const len = (a) => Math.sqrt(dot(a, a));

// Parses the hash (with or without its '#'). Returns {eye, look, up, fov, ortho} with the fields present, or null
// when it holds none of them. Throws Error naming the field for a malformed value (three finite numbers, fov in
// (0, 180), ortho > 0), so the page can say what is wrong.
export function parseHash(hash) {
  const text = hash.startsWith('#') ? hash.slice(1) : hash;
  if (!text) return null;
  const out = {};
  for (const part of text.split('&')) {
    if (!part) continue;
    const eq = part.indexOf('=');
    const name = decodeURIComponent(eq < 0 ? part : part.slice(0, eq));
    const value = eq < 0 ? '' : decodeURIComponent(part.slice(eq + 1));
    if (name === 'eye' || name === 'look' || name === 'up') {
      const v = value.split(',').map((s) => (s.trim() === '' ? NaN : Number(s)));
      if (v.length !== 3 || !v.every(Number.isFinite)) throw new Error(`hash: ${name} needs three numbers x,y,z`);
      out[name] = v;
    } else if (name === 'fov') {
      const v = value.trim() === '' ? NaN : Number(value);
      if (!(v > 0 && v < 180)) throw new Error('hash: fov must be between 0 and 180 degrees');
      out.fov = v;
    } else if (name === 'ortho') {
      const v = value.trim() === '' ? NaN : Number(value);
      if (!(v > 0 && Number.isFinite(v))) throw new Error('hash: ortho must be a positive height');
      out.ortho = v;
    }
    // Other names are left for other uses of the hash.
  }
  if ((out.eye === undefined) !== (out.look === undefined)) throw new Error('hash: eye and look go together');
  return Object.keys(out).length ? out : null;
}

const num = (x) => String(Number(x.toPrecision(9)));
const triple = (v) => v.map(num).join(',');

// The hash of a camera {eye, look, up, fov} or, orthographic, {eye, look, up, ortho}.
export function formatHash(cam) {
  let h = `#eye=${triple(cam.eye)}&look=${triple(cam.look)}&up=${triple(cam.up)}`;
  h += cam.orthographic ? `&ortho=${num(cam.orthoHeight)}` : `&fov=${num(cam.fov)}`;
  return h;
}

// The camera to show: the file's camera (decoded header: {orthographic, eye, direction, up, fov, orthoHeight}) with
// the hash's fields applied as vox-trace applies its flags: eye and look make a perspective camera with the file
// camera's up and its fov (45 when the file's camera is orthographic); up and fov then replace theirs; fov makes it
// perspective. `centre` picks the orbit target of the file's camera: the point of its view line nearest the grid's
// centre (its look point when it looks away). Returns {orthographic, eye, look, up, fov, orthoHeight}.
export function resolveCamera(file, hash, centre) {
  let cam = {
    orthographic: file.orthographic,
    eye: file.eye.slice(),
    up: file.up.slice(),
    fov: file.fov,
    orthoHeight: file.orthoHeight,
    spanLonger: Boolean(file.spanLonger),
  };
  const d = len(file.direction) > 0 ? scale(file.direction, 1 / len(file.direction)) : [0, 0, -1];
  const along = dot(sub(centre, file.eye), d);
  cam.look = add(file.eye, scale(d, along > 0 ? along : 1));
  if (hash && hash.eye) {
    cam = {
      orthographic: false,
      eye: hash.eye.slice(),
      look: hash.look.slice(),
      up: file.up.slice(),
      fov: file.orthographic ? 45 : file.fov,
      orthoHeight: file.orthoHeight,
      // The file's angle keeps the side it spans (vox-trace: moving the eye keeps the framing's width).
      spanLonger: !file.orthographic && Boolean(file.spanLonger),
    };
    if (!(len(sub(cam.look, cam.eye)) > 0)) throw new Error('hash: eye and look must differ');
  }
  if (hash && hash.up) cam.up = hash.up.slice();
  // The hash's fov and ortho are vertical, as vox-trace's --fov is.
  if (hash && hash.fov !== undefined) {
    cam.orthographic = false;
    cam.fov = hash.fov;
    cam.spanLonger = false;
  } else if (hash && hash.ortho !== undefined) {
    cam.orthographic = true;
    cam.orthoHeight = hash.ortho;
    cam.spanLonger = false;
  }
  const dir = sub(cam.look, cam.eye);
  const u = cam.up;
  const c = [dir[1] * u[2] - dir[2] * u[1], dir[2] * u[0] - dir[0] * u[2], dir[0] * u[1] - dir[1] * u[0]];
  if (!(len(c) > 0)) throw new Error('camera: up must not be parallel to the view direction');
  return cam;
}

// The vertical field of view (degrees) and image height of a resolved camera on an image of width / height
// `aspect`: a camera spanning the longer side spreads its angle or size across the width of a wide image, as
// vox-trace renders it (tan of the half angle, or the size, scaled by height / width).
export function verticalView(cam, aspect) {
  if (!cam.spanLonger || !(aspect > 1)) return { fov: cam.fov, orthoHeight: cam.orthoHeight };
  const half = Math.atan(Math.tan((cam.fov * Math.PI) / 360) / aspect);
  return { fov: (half * 360) / Math.PI, orthoHeight: cam.orthoHeight / aspect };
}
