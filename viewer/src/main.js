// The viewer page (DESIGN.md "Viewer page"): reads the grid's data from the page itself (data.js), draws the merged
// exposed surface with three.js, and offers orbit/pan/zoom, a slice plane, overlays and the cell under the pointer.
// Everything the page needs is in the file: no fetch, no worker, no font.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

import { decodeViewerData, layoutFromElements } from './data.js';
import { formatHash, parseHash, resolveCamera, verticalView } from './camera.js';
import { Cells } from './cells.js';
import { cubes, fieldMaterial, surfaceMaterial } from './surface.js';
import { availableFields, fieldQuads, keptLayer, showsField } from './field.js';
import { blockFactor, blockSurface } from './lod.js';
import { buildPanel } from './panel.js';

// Surfaces of more triangles than this get a coarse stand-in of about LOD_TRIANGLES (lod.js).
const LOD_FROM_TRIANGLES = 1500000;
const LOD_TRIANGLES = 300000;

// Colours pass through unchanged: the page shows vox-export's sRGB bytes as they are, like the mesh files do.
THREE.ColorManagement.enabled = false;

const api = { ready: false, error: null };
window.voxViewer = api;

function fail(message) {
  api.error = message;
  const box = document.getElementById('vox-error') || document.body.appendChild(document.createElement('pre'));
  box.id = 'vox-error';
  box.textContent = message;
  box.style.cssText = 'position:fixed;left:1em;bottom:1em;color:#fff;background:#a00;padding:.5em;font:13px monospace';
  console.error(`libvox viewer: ${message}`);
}

async function start() {
  const elements = [...document.querySelectorAll('script[type="application/x-vox-data"]')].map((s) => ({
    text: s.textContent,
    encoding: s.dataset.encoding,
    bytes: s.dataset.bytes,
  }));
  // Milliseconds since navigation began at each stage, for bench/viewer_bench.mjs.
  const timings = { scriptStart: performance.now() };
  api.timings = timings;
  const data = decodeViewerData(await layoutFromElements(elements));
  timings.decoded = performance.now();
  api.data = data;
  const cells = new Cells(data);
  timings.cellsIndexed = performance.now();
  api.cells = cells;

  const canvas = document.createElement('canvas');
  canvas.id = 'vox-canvas';
  document.body.appendChild(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const bg = data.background.map((x) => Math.round(Math.min(Math.max(x, 0), 1) * 255) / 255);
  renderer.setClearColor(new THREE.Color(bg[0], bg[1], bg[2]), 1);
  renderer.localClippingEnabled = false;

  const scene = new THREE.Scene();
  // Everything is placed relative to the grid's centre, so float32 keeps the detail of grids far from the origin.
  const centre = data.centre;
  const ext = [0, 1, 2].map((a) => data.hi[a] - data.lo[a]);
  const cellSize = ext.map((e, a) => e / data.dims[a]);
  const origin = [0, 1, 2].map((a) => data.lo[a] - centre[a]);
  const toLattice = (p) => [0, 1, 2].map((a) => (p[a] - origin[a]) / cellSize[a]);
  const fromLattice = (p) => [0, 1, 2].map((a) => origin[a] + p[a] * cellSize[a]);

  // The voxels: the merged surface, and the faces that close a cut (rebuilt when the slice moves).
  const surface = surfaceMaterial(data, origin, cellSize);
  const voxels = new THREE.Group();
  scene.add(voxels);
  let fullMesh = null;
  const drawCubes = new URLSearchParams(window.location.search).get('voxels') === 'cubes';
  if (drawCubes && cells.total > 0) {
    const material = surfaceMaterial(data, origin, cellSize, true);
    material.uniforms = surface.uniforms;  // one slice and one set of toggles for both
    voxels.add(cubes(cells, material));
  } else if (data.triangleCount > 0) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('lattice', new THREE.BufferAttribute(data.vertices, 3));
    if (data.hasColors) g.setAttribute('vcolor', new THREE.BufferAttribute(data.vertexColors, 3, true));
    g.setIndex(new THREE.BufferAttribute(data.triangles, 1));
    g.boundingSphere = new THREE.Sphere(new THREE.Vector3(), 0.5 * Math.hypot(...ext));
    const mesh = new THREE.Mesh(g, surface);
    mesh.frustumCulled = false;
    voxels.add(mesh);
    fullMesh = mesh;
  }
  let capMesh = null;
  // The slice plane's field (field.js): signed distances or volume fractions on the kept layer, when the grid has
  // them; 'voxels' draws the plane as grids without them do.
  let fieldMesh = null;
  let field = availableFields(data)[0];
  const fieldMat = fieldMaterial(surface);
  // Large surfaces: a coarse stand-in (lod.js) for the first frame and while the camera moves.
  const lod = { mesh: null, factor: 1, coarse: false, timer: 0 };
  api.lod = lod;
  // ?lod=N: the stand-in from N triangles on (tests use a small N).
  const lodFrom = Number(new URLSearchParams(window.location.search).get('lod') ?? LOD_FROM_TRIANGLES);
  if (fullMesh && data.triangleCount > lodFrom) {
    lod.factor = blockFactor(data.triangleCount, Math.min(LOD_TRIANGLES, lodFrom));
    const blocks = blockSurface(cells, lod.factor);
    const g = new THREE.BufferGeometry();
    g.setAttribute('lattice', new THREE.BufferAttribute(blocks.lattice, 3));
    if (blocks.colors) g.setAttribute('vcolor', new THREE.BufferAttribute(blocks.colors, 3, true));
    g.setIndex(new THREE.BufferAttribute(Uint32Array.from({ length: 6 * blocks.faces }, (_, v) => v), 1));
    lod.mesh = new THREE.Mesh(g, surface);
    lod.mesh.frustumCulled = false;
    lod.faces = blocks.faces;
    voxels.add(lod.mesh);
    lod.coarse = true;
  }
  timings.built = performance.now();

  // Overlays: the grid's bounds, the scene's triangles and spheres.
  const boundsLines = new THREE.LineSegments(
    new THREE.EdgesGeometry(new THREE.BoxGeometry(ext[0], ext[1], ext[2])),
    new THREE.LineBasicMaterial({ color: 0x222222 }),
  );
  scene.add(boundsLines);
  const overlay = new THREE.Group();
  overlay.visible = false;
  scene.add(overlay);
  const sceneBox = new THREE.Box3(new THREE.Vector3(...origin), new THREE.Vector3(...origin.map((o, a) => o + ext[a])));
  if (data.sceneTriangleCount > 0) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(data.sceneTriangles, 3));
    g.computeBoundingBox();
    sceneBox.union(g.boundingBox);
    overlay.add(new THREE.Mesh(g, new THREE.MeshBasicMaterial({ color: 0x1a1a1a, wireframe: true })));
  }
  for (let s = 0; s < data.sphereCount; ++s) {
    const m = data.spheres.subarray(12 * s, 12 * s + 12);
    const mesh = new THREE.Mesh(
      new THREE.SphereGeometry(1, 24, 12),
      new THREE.MeshBasicMaterial({ color: 0x1a1a1a, wireframe: true }),
    );
    mesh.matrixAutoUpdate = false;
    mesh.matrix.set(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11], 0, 0, 0, 1);
    mesh.updateMatrixWorld(true);
    sceneBox.union(new THREE.Box3().setFromObject(mesh));
    overlay.add(mesh);
  }
  // The level surface d = 0 of the band (vox-export --surface), when the page has one: shown beside the voxels,
  // switched on in the panel; shaded by its normals (the page has no lights), not cut by the slice plane.
  let levelMesh = null;
  if (data.hasLevelSurface && data.levelTriangleCount > 0) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(data.levelVertices, 3));
    g.setIndex(new THREE.BufferAttribute(data.levelTriangles, 1));
    g.computeVertexNormals();
    levelMesh = new THREE.Mesh(g, new THREE.MeshNormalMaterial());
    levelMesh.visible = false;
    scene.add(levelMesh);
  }
  api.levelMesh = levelMesh;
  const pickBox = new THREE.LineSegments(
    new THREE.EdgesGeometry(new THREE.BoxGeometry(1, 1, 1)),
    new THREE.LineBasicMaterial({ color: 0xff2a00, depthTest: false }),
  );
  pickBox.visible = false;
  pickBox.renderOrder = 10;
  scene.add(pickBox);

  // The camera: the hash's, else the grid file's.
  let view = null;
  let camera = null;
  let controls = null;
  const fileCamera = data.camera;
  const rel = (p) => [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
  const abs = (p) => [p[0] + centre[0], p[1] + centre[1], p[2] + centre[2]];
  let render = () => {};
  let userMoved = false;
  let hashTimer = 0;

  function applyCamera(cam) {
    view = cam;
    const aspect = Math.max(1, canvas.clientWidth) / Math.max(1, canvas.clientHeight);
    const vertical = verticalView(cam, aspect);
    if (cam.orthographic) {
      const h = 0.5 * vertical.orthoHeight;
      camera = new THREE.OrthographicCamera(-h * aspect, h * aspect, h, -h, 0, 1);
    } else {
      camera = new THREE.PerspectiveCamera(vertical.fov, aspect, 0.1, 1);
    }
    camera.up.set(...cam.up);
    camera.position.set(...rel(cam.eye));
    camera.lookAt(new THREE.Vector3(...rel(cam.look)));
    if (controls) controls.dispose();
    // OrbitControls turns the camera to its target (the origin) when made: give it the look point, then look there.
    controls = new OrbitControls(camera, canvas);
    controls.target.set(...rel(cam.look));
    controls.update();
    camera.lookAt(controls.target);
    controls.zoomToCursor = true;
    controls.addEventListener('start', () => {
      userMoved = true;
      setCoarse(true);
    });
    controls.addEventListener('end', () => setCoarse(false, 400));
    controls.addEventListener('change', () => {
      render();
      if (userMoved) {
        clearTimeout(hashTimer);
        hashTimer = setTimeout(writeHash, 150);
      }
    });
    render();
  }

  // The camera as it is now, in world coordinates, for the hash.
  function currentView() {
    const eye = abs(camera.position.toArray());
    const look = abs(controls.target.toArray());
    const up = camera.up.toArray();
    if (camera.isOrthographicCamera)
      return { orthographic: true, eye, look, up, orthoHeight: (camera.top - camera.bottom) / camera.zoom };
    return { orthographic: false, eye, look, up, fov: camera.fov };
  }
  function writeHash() {
    const h = formatHash(currentView());
    if (h !== window.location.hash) history.replaceState(null, '', h);
    api.hash = h;
  }

  function fromHash() {
    let parsed = null;
    try {
      parsed = parseHash(window.location.hash);
    } catch (e) {
      fail(e.message);
    }
    userMoved = false;
    applyCamera(resolveCamera(fileCamera, parsed, centre));
  }

  // Near and far planes that hold the grid and the scene's primitives: near as far as it can go (a little in front
  // of the box's nearest depth), so depth keeps its precision; a box reaching behind the eye gets a near plane of
  // 1e-5 of the far one.
  const corner = new THREE.Vector3();
  function fitClipPlanes() {
    if (camera.isOrthographicCamera) {
      // vox-trace's orthographic rays start on the camera's plane: nothing behind it is drawn.
      let far = 0;
      const dir = new THREE.Vector3();
      camera.getWorldDirection(dir);
      for (let c = 0; c < 8; ++c) {
        corner.set(
          c & 1 ? sceneBox.max.x : sceneBox.min.x,
          c & 2 ? sceneBox.max.y : sceneBox.min.y,
          c & 4 ? sceneBox.max.z : sceneBox.min.z,
        );
        far = Math.max(far, corner.sub(camera.position).dot(dir));
      }
      camera.near = 0;
      camera.far = Math.max(far * 1.01, 1e-9);
    } else {
      // Depth along the view direction is linear, so the box's nearest and farthest depths are at its corners.
      const dir = new THREE.Vector3();
      camera.getWorldDirection(dir);
      let far = 0;
      let nearest = Infinity;
      for (let c = 0; c < 8; ++c) {
        corner.set(
          c & 1 ? sceneBox.max.x : sceneBox.min.x,
          c & 2 ? sceneBox.max.y : sceneBox.min.y,
          c & 4 ? sceneBox.max.z : sceneBox.min.z,
        );
        const depth = corner.sub(camera.position).dot(dir);
        far = Math.max(far, depth);
        nearest = Math.min(nearest, depth);
      }
      far = Math.max(far * 1.01, 1e-9);
      camera.near = Math.max(nearest * 0.99, far * 1e-5);
      camera.far = far;
    }
    camera.updateProjectionMatrix();
  }

  function resize() {
    const w = window.innerWidth;
    const h = window.innerHeight;
    renderer.setSize(w, h);
    if (!camera) return;
    if (camera.isOrthographicCamera) {
      const half = 0.5 * (camera.top - camera.bottom);
      camera.left = -half * (w / h);
      camera.right = half * (w / h);
    } else {
      camera.aspect = w / h;
    }
    camera.updateProjectionMatrix();
    render();
  }

  // Renders at most once per animation frame.
  let pending = false;
  let frames = 0;
  // The coarse stand-in now, or the full surface (after `delay` ms without another call).
  function setCoarse(coarse, delay = 0) {
    if (!lod.mesh) return;
    clearTimeout(lod.timer);
    if (coarse) {
      lod.coarse = true;
      return;
    }
    lod.timer = setTimeout(() => {
      lod.coarse = false;
      render();
    }, delay);
  }
  render = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      fitClipPlanes();
      if (lod.mesh) {
        lod.mesh.visible = lod.coarse;
        fullMesh.visible = !lod.coarse;
        if (capMesh) capMesh.visible = !lod.coarse;
      }
      if (!timings.firstRender) timings.firstRender = performance.now();
      if (!lod.coarse && !timings.firstFullRender) timings.firstFullRender = performance.now();
      renderer.render(scene, camera);
      api.drawnTriangles = renderer.info.render.triangles;  // for tests: what the last frame drew
      ++frames;
      api.frames = frames;
      if (!api.ready) {
        // The frame is on screen once the next one starts.
        requestAnimationFrame(() => {
          api.firstFrameMs = performance.now();
          timings.firstFrame = api.firstFrameMs;
          // The first frame of a large grid was the coarse one: now the full surface.
          setCoarse(false, 0);
          api.ready = true;
          document.body.dataset.ready = '1';
        });
      }
    });
  };

  // Slice: keep the voxels below (or, flipped, at and above) a lattice plane; close the cut with cap faces.
  const slice = { axis: -1, pos: 0, keepBelow: true };
  function setSlice(axis, pos, keepBelow = slice.keepBelow) {
    slice.axis = axis;
    slice.pos = axis < 0 ? 0 : Math.min(Math.max(Math.round(pos), 0), data.dims[axis]);
    slice.keepBelow = keepBelow;
    surface.uniforms.uSliceAxis.value = slice.axis;
    surface.uniforms.uSlicePos.value = slice.pos;
    surface.uniforms.uSliceSign.value = keepBelow ? 1 : -1;
    if (capMesh) {
      voxels.remove(capMesh);
      capMesh.geometry.dispose();
      capMesh = null;
    }
    const caps = cells.capFaces(slice.axis, slice.pos, keepBelow);
    if (caps.count > 0) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('lattice', new THREE.BufferAttribute(caps.positions, 3));
      if (caps.colors) g.setAttribute('vcolor', new THREE.BufferAttribute(caps.colors, 3, true));
      // Drawn by index: three.js takes the count of an unindexed draw from a `position` attribute, which the
      // lattice-placed geometry does not have.
      g.setIndex(new THREE.BufferAttribute(Uint32Array.from({ length: 6 * caps.count }, (_, v) => v), 1));
      capMesh = new THREE.Mesh(g, surface);
      capMesh.frustumCulled = false;
      voxels.add(capMesh);
    }
    buildField();
    const shown = cells.keptCount(slice.axis, slice.pos, keepBelow);
    api.shownVoxels = shown;
    api.capFaces = caps.count;
    panel.setShown(shown, cells.total);
    pick.refresh();
    render();
  }
  // The field's quads on the slice plane, rebuilt with the slice or the field.
  function buildField() {
    if (fieldMesh) {
      voxels.remove(fieldMesh);
      fieldMesh.geometry.dispose();
      fieldMesh = null;
    }
    const quads = fieldQuads(cells, field, slice.axis, slice.pos, slice.keepBelow);
    api.fieldCells = quads.count;
    api.field = field;
    if (quads.count === 0) return;
    const g = new THREE.BufferGeometry();
    g.setAttribute('lattice', new THREE.BufferAttribute(quads.positions, 3));
    g.setAttribute('vcolor', new THREE.BufferAttribute(quads.colors, 3, true));
    g.setIndex(new THREE.BufferAttribute(Uint32Array.from({ length: 6 * quads.count }, (_, v) => v), 1));
    fieldMesh = new THREE.Mesh(g, fieldMat);
    fieldMesh.frustumCulled = false;
    voxels.add(fieldMesh);
  }
  function setField(f) {
    field = f;
    buildField();
    pick.refresh();
    render();
  }
  const keepCell = (i, j, k) => {
    if (slice.axis < 0) return true;
    const x = [i, j, k][slice.axis];
    return slice.keepBelow ? x < slice.pos : x >= slice.pos;
  };

  // The voxel under the pointer: the first drawn voxel along the pixel's ray (the cells walked in JavaScript, not
  // read back from the GPU: exact and cheap).
  const raycaster = new THREE.Raycaster();
  const pick = {
    hover: null,
    pinned: null,
    at(clientX, clientY) {
      const rect = canvas.getBoundingClientRect();
      const ndc = new THREE.Vector2(
        ((clientX - rect.left) / rect.width) * 2 - 1,
        1 - ((clientY - rect.top) / rect.height) * 2,
      );
      raycaster.setFromCamera(ndc, camera);
      const o = toLattice(raycaster.ray.origin.toArray());
      const d = raycaster.ray.direction.toArray().map((x, a) => x / cellSize[a]);
      // Voxels, and the cells whose field the slice plane shows (the band's empty cells too).
      const layer = keptLayer(data.dims, slice.axis, slice.pos, slice.keepBelow);
      const shows = (i, j, k) =>
        keepCell(i, j, k) && (cells.isVoxel(i, j, k) || showsField(cells, field, slice.axis, layer, i, j, k));
      const hit = cells.firstCell(o, d, shows);
      return hit ? cells.info(...hit.ijk) : null;
    },
    show() {
      const cell = this.pinned || this.hover;
      api.picked = cell;
      panel.setCell(cell, !!this.pinned);
      if (cell) {
        const lo = fromLattice(cell.ijk);
        pickBox.scale.set(...cellSize);
        pickBox.position.set(...lo.map((x, a) => x + 0.5 * cellSize[a]));
      }
      pickBox.visible = !!cell;
      render();
    },
    refresh() {
      if (this.pinned && !keepCell(...this.pinned.ijk)) this.pinned = null;
      if (this.hover && !keepCell(...this.hover.ijk)) this.hover = null;
      this.show();
    },
  };

  const panel = buildPanel(data, cells, {
    slice: (axis, pos, keepBelow) => setSlice(axis, pos, keepBelow),
    field: (f) => setField(f),
    toggle: (what, on) => {
      if (what === 'triangles') overlay.visible = on;
      else if (what === 'bounds') boundsLines.visible = on;
      else if (what === 'lines') surface.uniforms.uLines.value = on ? 1 : 0;
      else if (what === 'voxels') voxels.visible = on;
      else if (what === 'level' && levelMesh) levelMesh.visible = on;
      render();
    },
    resetCamera: () => {
      history.replaceState(null, '', window.location.pathname + window.location.search);
      fromHash();
    },
  });

  let downAt = null;
  canvas.addEventListener('pointerdown', (e) => {
    downAt = [e.clientX, e.clientY];
  });
  canvas.addEventListener('pointerup', (e) => {
    // A click, not the end of a drag: pin the voxel under the pointer (or unpin on empty space).
    if (downAt && Math.hypot(e.clientX - downAt[0], e.clientY - downAt[1]) < 4) {
      pick.pinned = pick.at(e.clientX, e.clientY);
      pick.show();
    }
    downAt = null;
  });
  let hoverFrame = 0;
  canvas.addEventListener('pointermove', (e) => {
    if (e.buttons) return;
    cancelAnimationFrame(hoverFrame);
    hoverFrame = requestAnimationFrame(() => {
      pick.hover = pick.at(e.clientX, e.clientY);
      if (!pick.pinned) pick.show();
    });
  });
  canvas.addEventListener('pointerleave', () => {
    pick.hover = null;
    if (!pick.pinned) pick.show();
  });

  window.addEventListener('resize', resize);
  window.addEventListener('hashchange', fromHash);
  window.addEventListener('keydown', (e) => {
    if (e.key === 'h' && !(e.target instanceof HTMLInputElement)) panel.toggleHidden();
  });

  // For bench/viewer_bench.mjs: renders `n` frames, turning the camera a little about the orbit target each time
  // (as a drag does), each one waited for (a one-pixel read-back); milliseconds per frame.
  api.timeFrames = (n, coarse = false) => {
    if (lod.mesh) {
      lod.mesh.visible = coarse;
      fullMesh.visible = !coarse;
    }
    const gl = renderer.getContext();
    const pixel = new Uint8Array(4);
    const t0 = performance.now();
    for (let f = 0; f < n; ++f) {
      const offset = camera.position.clone().sub(controls.target);
      offset.applyAxisAngle(camera.up, 0.05);
      camera.position.copy(controls.target).add(offset);
      camera.lookAt(controls.target);
      fitClipPlanes();
      renderer.render(scene, camera);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    }
    return (performance.now() - t0) / n;
  };
  api.setSlice = setSlice;
  api.setField = setField;
  api.pickAt = (x, y) => pick.at(x, y);
  api.view = () => currentView();
  api.render = render;
  api.setPanelHidden = (hidden) => panel.setHidden(hidden);

  renderer.setSize(window.innerWidth, window.innerHeight);
  fromHash();
  setSlice(-1, 0, true);
}

start().catch((e) => fail(e && e.message ? e.message : String(e)));
