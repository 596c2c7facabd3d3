// Reads the binary layout that vox-export writes into the page (docs/viewer-format.md, libvox
// export/viewer_page.cpp). Plain typed-array views over one ArrayBuffer: nothing is copied but the title.
// Runs in the browser and under Node (tests/viewer/data_test.mjs).

export const VERSION = 1;
export const HEADER_BYTES = 256;
const MAGIC = 'VOXVIEW\0';

export class LayoutError extends Error {}

// Decodes base64 text into bytes: Uint8Array.fromBase64 where the browser has it, else atob.
export function base64ToBytes(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text);
  if (typeof Buffer !== 'undefined') return new Uint8Array(Buffer.from(text, 'base64'));
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// The layout from the page's <script type="application/x-vox-data"> elements ({text, encoding, bytes} each, in
// document order): their base64 texts joined, inflated when the encoding is "deflate" (a zlib stream, as
// vox-export writes it; DecompressionStream, in every current browser and in Node 18+). Resolves to a Uint8Array.
export async function layoutFromElements(elements) {
  const joined = bytesFromChunks(elements.map((e) => e.text));
  const encoding = elements.length ? elements[0].encoding : '';
  if (!encoding) return joined;
  if (encoding !== 'deflate') throw new LayoutError(`viewer data: unknown encoding ${encoding}`);
  const stream = new Blob([joined]).stream().pipeThrough(new DecompressionStream('deflate'));
  let out;
  try {
    out = new Uint8Array(await new Response(stream).arrayBuffer());
  } catch (e) {
    throw new LayoutError(`viewer data: cannot inflate (${e.message})`);
  }
  const want = Number(elements[0].bytes);
  if (elements[0].bytes !== undefined && out.length !== want)
    throw new LayoutError(`viewer data: ${out.length} bytes inflated, the page says ${want}`);
  return out;
}

// One buffer from base64 texts, in order.
export function bytesFromChunks(texts) {
  const parts = texts.map((t) => base64ToBytes(t.trim()));
  const total = parts.reduce((n, p) => n + p.length, 0);
  const out = new Uint8Array(total);
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
}

const WIDTH = [1, 2, 4];
function uintArray(width) {
  return width === 1 ? Uint8Array : width === 2 ? Uint16Array : Uint32Array;
}

// Decodes `bytes` (a Uint8Array whose byteOffset is a multiple of 8). Throws LayoutError for a wrong magic, version
// or size: the page says so instead of drawing garbage.
export function decodeViewerData(bytes) {
  if (bytes.byteOffset % 8 !== 0) bytes = bytes.slice();
  const buffer = bytes.buffer;
  const base = bytes.byteOffset;
  if (bytes.length < HEADER_BYTES) throw new LayoutError(`viewer data: ${bytes.length} bytes, shorter than the header`);
  const view = new DataView(buffer, base, bytes.length);
  const magic = String.fromCharCode(...bytes.subarray(0, 8));
  if (magic !== MAGIC) throw new LayoutError('viewer data: not a libvox viewer layout (bad magic)');
  const version = view.getUint32(8, true);
  if (version !== VERSION) throw new LayoutError(`viewer data: layout version ${version}, this page reads ${VERSION}`);
  const flags = view.getUint32(12, true);
  const f64 = (o) => view.getFloat64(o, true);
  const u32 = (o) => view.getUint32(o, true);
  const vec = (o) => [f64(o), f64(o + 8), f64(o + 16)];
  const d = {
    version,
    hasColors: (flags & 1) !== 0,
    wide: (flags & 2) !== 0,
    countWidth: WIDTH[(flags >> 2) & 3],
    paletteWidth: WIDTH[(flags >> 4) & 3],
    lo: vec(16),
    hi: vec(40),
    dims: [u32(64), u32(68), u32(72)],
    colorMode: ['count', 'material', 'none'][u32(76)] ?? 'none',
    camera: {
      orthographic: (flags & 64) !== 0,
      spanLonger: (flags & 128) !== 0,
      eye: vec(80),
      direction: vec(104),
      up: vec(128),
      fov: f64(152),
      orthoHeight: f64(160),
    },
    background: [view.getFloat32(168, true), view.getFloat32(172, true), view.getFloat32(176, true)],
    solidColor: [bytes[180], bytes[181], bytes[182]],
    maxCount: u32(184),
    vertexCount: u32(188),
    triangleCount: u32(192),
    paletteCount: u32(196),
    rowCount: u32(200),
    occupiedCount: u32(204),
    solidRunCount: u32(208),
    idsPerCell: u32(212),
    idCount: u32(216),
    sceneTriangleCount: u32(220),
    sphereCount: u32(224),
    primitiveCount: u32(228),
    planeCount: u32(236),
    // Flags bits 8 and 9: the grid's signed-distance band and volume fractions (issue 38), arrays at the end.
    hasDistances: (flags & 256) !== 0,
    hasFractions: (flags & 512) !== 0,
    // Flag bit 10: the level surface d = 0 of the band (issue 47, vox-export --surface), arrays at the very end.
    hasLevelSurface: (flags & 1024) !== 0,
    levelVertexCount: 0,
    levelTriangleCount: 0,
    bandCount: 0,
    bandRowCount: 0,
    halfWidth: 0,
  };
  if (d.hasDistances) {
    d.bandCount = u32(240);
    d.bandRowCount = u32(244);
    d.halfWidth = f64(248);
  }
  const titleBytes = u32(232);
  d.centre = [0, 1, 2].map((a) => (d.lo[a] + d.hi[a]) * 0.5);

  let at = HEADER_BYTES;
  const take = (Type, count) => {
    const size = Type.BYTES_PER_ELEMENT * count;
    if (at + size > bytes.length)
      throw new LayoutError(`viewer data: truncated at byte ${bytes.length} (an array needs ${at + size})`);
    const array = new Type(buffer, base + at, count);
    at = Math.ceil((at + size) / 8) * 8;
    return array;
  };
  d.title = new TextDecoder().decode(take(Uint8Array, titleBytes));
  const Coord = d.wide ? Uint32Array : Uint16Array;
  d.vertices = take(Coord, 3 * d.vertexCount);
  d.vertexColors = d.hasColors ? take(Uint8Array, 3 * d.vertexCount) : null;
  d.triangles = take(Uint32Array, 3 * d.triangleCount);
  d.palette = d.hasColors ? take(Uint8Array, 3 * d.paletteCount) : null;
  d.rowKeys = take(Uint32Array, d.rowCount);
  d.rowStart = take(Uint32Array, d.rowCount + 1);
  d.cellI = take(Coord, d.occupiedCount);
  d.cellCount = take(uintArray(d.countWidth), d.occupiedCount);
  d.cellColor = d.hasColors ? take(uintArray(d.paletteWidth), d.occupiedCount) : null;
  d.ids = take(Uint32Array, d.idCount);
  d.solidRuns = take(Float64Array, 2 * d.solidRunCount);
  d.sceneTriangles = take(Float32Array, 9 * d.sceneTriangleCount);
  d.spheres = take(Float32Array, 12 * d.sphereCount);
  d.bandRowKeys = d.hasDistances ? take(Uint32Array, d.bandRowCount) : null;
  d.bandRowStart = d.hasDistances ? take(Uint32Array, d.bandRowCount + 1) : null;
  d.bandI = d.hasDistances ? take(Coord, d.bandCount) : null;
  d.distances = d.hasDistances ? take(Float32Array, d.bandCount) : null;
  d.fractions = d.hasFractions ? take(Float32Array, d.occupiedCount) : null;
  d.levelVertices = null;
  d.levelTriangles = null;
  if (d.hasLevelSurface) {
    const counts = take(Uint32Array, 2);
    d.levelVertexCount = counts[0];
    d.levelTriangleCount = counts[1];
    d.levelVertices = take(Float32Array, 3 * d.levelVertexCount);
    d.levelTriangles = take(Uint32Array, 3 * d.levelTriangleCount);
    for (let i = 0; i < d.levelTriangles.length; ++i)
      if (d.levelTriangles[i] >= d.levelVertexCount) throw new LayoutError('viewer data: a level-surface index out of range');
  }
  if (at !== bytes.length) throw new LayoutError(`viewer data: ${bytes.length} bytes, the layout ends at ${at}`);

  // Where each cell's stored ids start (min(count, idsPerCell) each, in cell order).
  d.idStart = new Uint32Array(d.occupiedCount + 1);
  for (let c = 0, s = 0; c < d.occupiedCount; ++c) {
    s += Math.min(d.cellCount[c], d.idsPerCell);
    d.idStart[c + 1] = s;
  }
  if (d.idStart[d.occupiedCount] !== d.idCount) throw new LayoutError('viewer data: stored ids do not match the counts');
  if (d.rowStart[d.rowCount] !== d.occupiedCount) throw new LayoutError('viewer data: rows do not cover the cells');
  if (d.hasDistances && d.bandRowStart[d.bandRowCount] !== d.bandCount)
    throw new LayoutError('viewer data: band rows do not cover the band');
  d.solidCount = 0;
  for (let r = 0; r < d.solidRunCount; ++r) d.solidCount += d.solidRuns[2 * r + 1];
  return d;
}
