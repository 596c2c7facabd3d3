// The voxels' material: vertices in integer lattice coordinates (the layout's), placed by lo + (hi - lo) * x / n
// in the vertex shader; each face flat-shaded by its axis, like a voxel editor; the slice plane and the cell lines
// done per fragment.
import * as THREE from 'three';

const vertexShader = /* glsl */ `
uniform vec3 uOrigin;
uniform vec3 uCell;
#ifdef VOX_INSTANCED
// One unit cube (three.js' BoxGeometry, centred on 0) per voxel, at the voxel's lattice corner.
attribute vec3 cell;
#else
attribute vec3 lattice;
#endif
#ifdef VOX_COLORS
attribute vec3 vcolor;
#endif
varying vec3 vLattice;
varying vec3 vView;
varying vec3 vColor;
void main() {
#ifdef VOX_INSTANCED
  vec3 lattice = cell + position + 0.5;
#endif
  vLattice = lattice;
  vec4 view = modelViewMatrix * vec4(uOrigin + lattice * uCell, 1.0);
  vView = view.xyz;
#ifdef VOX_COLORS
  vColor = vcolor;
#else
  vColor = vec3(0.8);
#endif
  gl_Position = projectionMatrix * view;
}
`;

const fragmentShader = /* glsl */ `
uniform int uSliceAxis;
uniform float uSlicePos;
uniform float uSliceSign;
uniform int uLines;
varying vec3 vLattice;
varying vec3 vView;
varying vec3 vColor;
void main() {
  // The face's normal from the lattice's screen derivatives (one per triangle), turned to the face's outside: the
  // surface's triangles run counter-clockwise seen from outside the voxels.
  vec3 n = normalize(cross(dFdx(vLattice), dFdy(vLattice)));
  n = gl_FrontFacing ? n : -n;
  vec3 an = abs(n);
  int axis = an.x > an.y ? (an.x > an.z ? 0 : 2) : (an.y > an.z ? 1 : 2);
  float side = axis == 0 ? sign(n.x) : axis == 1 ? sign(n.y) : sign(n.z);
#ifdef VOX_FLAT
  // The slice plane's field (fieldMaterial): on the plane, unlit, so the map's colours read as they are.
  float shade = 1.0;
#else
  if (uSliceAxis >= 0) {
    // The cell this fragment belongs to, half a cell inside the face: dropped when on the removed side.
    float coord = uSliceAxis == 0 ? vLattice.x : uSliceAxis == 1 ? vLattice.y : vLattice.z;
    if (axis == uSliceAxis) coord -= 0.5 * side;
    if (uSliceSign * (coord - uSlicePos) > 0.0) discard;
  }
  // Light by the face's axis (top brightest, bottom darkest), as voxel editors do: every face of a voxel reads.
  float shade = axis == 1 ? (side > 0.0 ? 1.0 : 0.55) : axis == 0 ? 0.82 : 0.68;
#endif
  vec3 color = vColor * shade;
  if (uLines == 1) {
    vec3 w = fwidth(vLattice);
    vec3 d = abs(fract(vLattice + 0.5) - 0.5) / max(w, vec3(1e-6));
    if (axis == 0) d.x = 1e9;
    if (axis == 1) d.y = 1e9;
    if (axis == 2) d.z = 1e9;
    float line = 1.0 - clamp(min(d.x, min(d.y, d.z)) - 0.5, 0.0, 1.0);
    color = mix(color, color * 0.35, line);
  }
  gl_FragColor = vec4(color, 1.0);
}
`;

// data: the decoded layout; origin: lo - centre; cell: (hi - lo) / dims. instanced: for cubes() below.
export function surfaceMaterial(data, origin, cell, instanced = false) {
  const defines = {};
  if (data.hasColors) defines.VOX_COLORS = 1;
  if (instanced) defines.VOX_INSTANCED = 1;
  return new THREE.ShaderMaterial({
    vertexShader,
    fragmentShader,
    defines,
    uniforms: {
      uOrigin: { value: new THREE.Vector3(...origin) },
      uCell: { value: new THREE.Vector3(...cell) },
      uSliceAxis: { value: -1 },
      uSlicePos: { value: 0 },
      uSliceSign: { value: 1 },
      uLines: { value: 0 },
    },
    side: THREE.DoubleSide,
  });
}

// The material of the slice plane's field quads (field.js): vertex colours, unlit, the surface's uniforms (cell
// lines). Drawn over the voxels' faces that lie on the plane: pulled towards the camera by a polygon offset, as
// the quads and those faces are coplanar.
export function fieldMaterial(surface) {
  return new THREE.ShaderMaterial({
    vertexShader,
    fragmentShader,
    defines: { VOX_COLORS: 1, VOX_FLAT: 1 },
    uniforms: surface.uniforms,
    side: THREE.DoubleSide,
    polygonOffset: true,
    polygonOffsetFactor: -1,
    polygonOffsetUnits: -4,
  });
}

// The other way to draw voxels, kept to measure against the merged surface (bench/viewer_bench.mjs; the page's
// `?voxels=cubes`): one instanced cube of 12 triangles per voxel, occupied and solid. The merged surface draws
// far fewer triangles and renders faster (README, "Viewer page").
export function cubes(cells, material) {
  const d = cells.d;
  const n = cells.total;
  const corner = new Float32Array(3 * n);
  const colors = d.hasColors ? new Uint8Array(3 * n) : null;
  let v = 0;
  const ny = d.dims[1];
  const put = (i, j, k, c) => {
    corner[3 * v] = i;
    corner[3 * v + 1] = j;
    corner[3 * v + 2] = k;
    if (colors) colors.set(cells.color(c), 3 * v);
    ++v;
  };
  for (let r = 0; r < d.rowCount; ++r) {
    const j = d.rowKeys[r] % ny;
    const k = (d.rowKeys[r] - j) / ny;
    for (let c = d.rowStart[r]; c < d.rowStart[r + 1]; ++c) put(d.cellI[c], j, k, c);
  }
  cells.forEachSolidSegment((i0, i1, j, k) => {
    for (let i = i0; i <= i1; ++i) put(i, j, k, -1);
  });
  const box = new THREE.BoxGeometry(1, 1, 1);
  const g = new THREE.InstancedBufferGeometry();
  g.setIndex(box.getIndex());
  g.setAttribute('position', box.getAttribute('position'));
  g.setAttribute('cell', new THREE.InstancedBufferAttribute(corner, 3));
  if (colors) g.setAttribute('vcolor', new THREE.InstancedBufferAttribute(colors, 3, true));
  g.instanceCount = n;
  const mesh = new THREE.Mesh(g, material);
  mesh.frustumCulled = false;
  return mesh;
}
