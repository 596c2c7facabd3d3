// The voxels' material: vertices in integer lattice coordinates (the layout's), placed by lo + (hi - lo) * x / n
// in the vertex shader; each face flat-shaded by its axis, like a voxel editor; the slice plane and the cell lines
// done per fragment.
import * as THREE from 'three';

const vertexShader = /* glsl */ `
uniform vec3 uOrigin;
uniform vec3 uCell;
attribute vec3 lattice;
#ifdef VOX_COLORS
attribute vec3 vcolor;
#endif
varying vec3 vLattice;
varying vec3 vView;
varying vec3 vColor;
void main() {
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
  if (uSliceAxis >= 0) {
    // The cell this fragment belongs to, half a cell inside the face: dropped when on the removed side.
    float coord = uSliceAxis == 0 ? vLattice.x : uSliceAxis == 1 ? vLattice.y : vLattice.z;
    if (axis == uSliceAxis) coord -= 0.5 * side;
    if (uSliceSign * (coord - uSlicePos) > 0.0) discard;
  }
  // Light by the face's axis (top brightest, bottom darkest), as voxel editors do: every face of a voxel reads.
  float shade = axis == 1 ? (side > 0.0 ? 1.0 : 0.55) : axis == 0 ? 0.82 : 0.68;
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

// data: the decoded layout; origin: lo - centre; cell: (hi - lo) / dims.
export function surfaceMaterial(data, origin, cell) {
  return new THREE.ShaderMaterial({
    vertexShader,
    fragmentShader,
    defines: data.hasColors ? { VOX_COLORS: 1 } : {},
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
