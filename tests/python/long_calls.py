"""The long Python calls and how Ctrl-C is measured on them: shared by tests/python/test_long_calls.py (one interrupt
each, a wide limit) and bench/python_ctrl_c.py (ten interrupts each, median and max against the 0.5 s promise).

    python3 long_calls.py CASE MOMENTS [BUNNY_PLY]     # in a fresh Python; prints one JSON line

A case makes its inputs in a fresh temporary folder (outside the clock), runs the call once uninterrupted (its
length, and for a save the old output), then once per moment: SIGINT sent at that fraction of the length, the time
from the signal to the KeyboardInterrupt measured. A save's old output must be left byte for byte and the folder
must hold no other file afterwards (no temporary file left). The module must work after the interrupts.
"""

import json
import os
import pathlib
import signal
import sys
import tempfile
import threading
import time

import numpy as np

import libvox

# Python turns SIGINT into KeyboardInterrupt only when its parent left SIGINT alone; a job started in the background
# by a non-interactive shell (as a CI runner may start us) inherits it ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)


def read_ply(path):
    """The bunny's vertices and faces (its ASCII PLY)."""
    with open(path) as f:
        counts = [int(l.split()[2]) for l in iter(f.readline, "end_header\n") if l.startswith("element")]
        v = np.loadtxt(f, max_rows=counts[0], usecols=(0, 1, 2))
        faces = np.loadtxt(f, max_rows=counts[1], usecols=(1, 2, 3), dtype=np.int64)
    return v, faces


def icosphere(subdivisions):
    """A closed, outward-oriented sphere of 20 * 4^subdivisions triangles, radius 1."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t), (t, 0, -1),
         (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid, out = {}, []

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = v[a] + v[b]
                v.append(m / np.linalg.norm(m))
                mid[key] = len(v) - 1
            return mid[key]

        for a, b, c in f:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = out
    return np.array(v), np.array(f, dtype=np.int64)


SPHERE_SCENE = """
Materials {{ numMaterials 1 Material {{ diffuseColor 1 1 1 }} }}
Group {{
    numObjects {count}
    MaterialIndex 0
{spheres}
}}
"""


def ball_scene(folder, count):
    """A course scene of `count` x `count` x `count` balls apart from each other (fractions refuse overlaps)."""
    spheres = "\n".join(f"    Sphere {{ center {x} {y} {z} radius 0.45 }}" for x in range(count) for y in range(count)
                        for z in range(count))
    path = folder / "balls.txt"
    path.write_text(SPHERE_SCENE.format(count=count ** 3, spheres=spheres))
    return path


def big_obj(folder, triangles):
    """An OBJ of `triangles` small triangles, each with its own three vertices (the parse is per line)."""
    rng = np.random.default_rng(3)
    block = 4096
    centres = rng.uniform(0, 1, size=(block, 3))
    lines = []
    for c in centres:
        for d in ((0, 0, 0), (0.01, 0, 0), (0, 0.01, 0)):
            lines.append("v %.6f %.6f %.6f\n" % tuple(c + d))
    vertex_text = "".join(lines).encode()
    path = folder / "big.obj"
    with open(path, "wb") as f:
        for _ in range(triangles // block):
            f.write(vertex_text)
        f.write("".join(f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}\n" for i in range(triangles - triangles % block
                                                                                    )).encode())
    return path


def big_ply(folder, triangles):
    """An ASCII PLY of `triangles` triangles over 3 * triangles vertices."""
    rng = np.random.default_rng(4)
    block = 4096
    v = rng.uniform(0, 1, size=(3 * block, 3))
    vertex_text = "".join("%.6f %.6f %.6f\n" % tuple(p) for p in v).encode()
    n = triangles // block * block
    path = folder / "big.ply"
    with open(path, "wb") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {3 * n}\nproperty float x\nproperty float y\n"
                f"property float z\nelement face {n}\nproperty list uchar int vertex_indices\nend_header\n".encode())
        for _ in range(n // block):
            f.write(vertex_text)
        f.write("".join(f"3 {3 * i} {3 * i + 1} {3 * i + 2}\n" for i in range(n)).encode())
    return path


def big_glb(folder, triangles):
    """A binary glTF of one mesh of `triangles` triangles (float32 positions, uint32 indices)."""
    rng = np.random.default_rng(5)
    # Small triangles, so that the voxelization at 4^3 after the read costs little.
    centres = rng.uniform(0, 1, size=(triangles, 1, 3))
    positions = (centres + np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0]])).reshape(-1, 3).astype(np.float32)
    indices = np.arange(3 * triangles, dtype=np.uint32)
    blob = positions.tobytes() + indices.tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "buffers": [{"byteLength": len(blob)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": positions.nbytes},
                           {"buffer": 0, "byteOffset": positions.nbytes, "byteLength": indices.nbytes}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3 * triangles, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 1]},
                         {"bufferView": 1, "componentType": 5125, "count": 3 * triangles, "type": "SCALAR"}]}
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    blob += b"\0" * (-len(blob) % 4)
    path = folder / "big.glb"
    with open(path, "wb") as f:
        f.write(b"glTF" + (2).to_bytes(4, "little") + (12 + 8 + len(js) + 8 + len(blob)).to_bytes(4, "little"))
        f.write(len(js).to_bytes(4, "little") + b"JSON" + js)
        f.write(len(blob).to_bytes(4, "little") + b"BIN\0" + blob)
    return path


def _bunny_grid(bunny, resolution, **kw):
    return libvox.voxelize(bunny, resolution=resolution, **kw)


def _rays(grid, count):
    lo, hi = np.array(grid.bounds[0]), np.array(grid.bounds[1])
    rng = np.random.default_rng(6)
    origins = np.tile(lo - (hi - lo), (count, 1))
    targets = rng.uniform(lo, hi, size=(count, 3))
    return origins, targets - origins


def _save(resolution, ext, fill=False, method="exact", **kw):
    def make(folder, bunny):
        grid = _bunny_grid(bunny, resolution, fill=fill, method=method)
        out = folder / f"out{ext}"
        return (lambda: grid.save(out, **kw)), out
    return make


def _setup_voxelize(folder, bunny):
    return lambda: libvox.voxelize(bunny, resolution=2048), None


def _setup_fill(folder, bunny):
    return lambda: libvox.voxelize(bunny, resolution=1024, fill=True), None


def _setup_ball_fractions(folder, bunny):
    scene = ball_scene(folder, 2)
    return lambda: libvox.voxelize(scene, resolution=120, fraction=True), None


def _setup_big_ball_fractions(folder, bunny):
    scene = ball_scene(folder, 1)
    return lambda: libvox.voxelize(scene, resolution=120, fraction=True), None


def _setup_big_ball(folder, bunny):
    """One ball is one primitive: its cell loop, 1.6 * 10^7 cells here, ran to its end before Ctrl-C acted."""
    scene = ball_scene(folder, 1)
    return lambda: libvox.voxelize(scene, resolution=250), None


def _setup_mesh_fractions(folder, bunny):
    v, f = icosphere(4)
    return lambda: libvox.voxelize((v, f), resolution=450, fraction=True), None


def _setup_sdf_band(folder, bunny):
    return lambda: libvox.voxelize(bunny, resolution=512, sdf=3), None


def _setup_sdf_dense(folder, bunny):
    return lambda: libvox.sdf(bunny, resolution=64), None


def _setup_batch(folder, bunny):
    v, f = read_ply(bunny)
    return lambda: libvox.voxelize_batch([(v, f)] * 12, 256), None


def _setup_distance(folder, bunny):
    grid = _bunny_grid(bunny, 64)
    lo, hi = np.array(grid.bounds[0]), np.array(grid.bounds[1])
    points = np.random.default_rng(1).uniform(lo, hi, size=(300_000, 3))
    grid.distance(points[:10])  # the search structure, built on the first call, outside the clock
    return lambda: grid.distance(points), None


def _setup_rays(which):
    def make(folder, bunny):
        grid = _bunny_grid(bunny, 256)
        o, d = _rays(grid, 2_000_000)
        getattr(grid, which)(o[:10], d[:10])  # the trace structure, built on the first call, outside the clock
        return (lambda: getattr(grid, which)(o, d)), None
    return make


def _setup_render(folder, bunny):
    grid = _bunny_grid(bunny, 64)
    libvox.render(grid, size=(4, 4))
    return lambda: libvox.render(grid, size=(1000, 1000), samples=16), None


def _setup_mesh(folder, bunny):
    grid = _bunny_grid(bunny, 512)
    return lambda: grid.mesh(color="count"), None


def _setup_colors(folder, bunny):
    grid = _bunny_grid(bunny, 2048)
    return lambda: grid.colors(), None


def _setup_load(folder, bunny):
    path = folder / "big.vgrid"
    _bunny_grid(bunny, 2048, fill=True, method="bbox").save(path)  # 508 MB: seconds to read
    return lambda: libvox.load(path), None


def _setup_pickle(folder, bunny):
    import pickle
    grid = _bunny_grid(bunny, 2048, method="bbox")
    return lambda: pickle.dumps(grid), None


def _setup_unpickle(folder, bunny):
    import pickle
    data = pickle.dumps(_bunny_grid(bunny, 2048, fill=True, method="bbox"))
    return lambda: pickle.loads(data), None


def _setup_read(make_file, triangles):
    def make(folder, bunny):
        path = make_file(folder, triangles)
        return lambda: libvox.voxelize(path, resolution=4), None
    return make


def _setup_read_course(folder, bunny):
    count = 600_000
    rng = np.random.default_rng(7)
    v = rng.uniform(0, 1, size=(3 * count, 3))
    tris = "\n".join("    Triangle { vertex0 %.5f %.5f %.5f vertex1 %.5f %.5f %.5f vertex2 %.5f %.5f %.5f }"
                     % tuple(v[3 * i:3 * i + 3].ravel()) for i in range(count))
    path = folder / "tris.txt"
    path.write_text(SPHERE_SCENE.format(count=count, spheres=tris))
    return lambda: libvox.voxelize(path, resolution=4), None


CASES = {
    "voxelize": _setup_voxelize,
    "fill": _setup_fill,
    "ball_fractions": _setup_ball_fractions,
    "big_ball_fractions": _setup_big_ball_fractions,
    "big_ball": _setup_big_ball,
    "mesh_fractions": _setup_mesh_fractions,
    "sdf_band": _setup_sdf_band,
    "sdf_dense": _setup_sdf_dense,
    "batch": _setup_batch,
    "distance": _setup_distance,
    "intersect": _setup_rays("intersect"),
    "occluded": _setup_rays("occluded"),
    "render": _setup_render,
    "mesh": _setup_mesh,
    "colors": _setup_colors,
    "load": _setup_load,
    "pickle": _setup_pickle,
    "unpickle": _setup_unpickle,
    "read_obj": _setup_read(big_obj, 1_000_000),
    "read_ply": _setup_read(big_ply, 600_000),
    "read_gltf": _setup_read(big_glb, 3_000_000),
    "read_course": _setup_read_course,
    # bbox: 1.1e8 cells, a 508 MB file, about 2 s to save (exact's 96 MB took 0.3-0.5 s: too short to tell).
    "save_vgrid": _save(2048, ".vgrid", fill=True, method="bbox"),
    "save_bricks": _save(1024, ".vgrid", bricks=(2, 2, 2)),
    "save_ply": _save(512, ".ply"),
    "save_obj": _save(512, ".obj"),
    "save_off": _save(512, ".off"),
    "save_stl": _save(512, ".stl"),
    "save_glb": _save(512, ".glb"),
    "save_gltf": _save(512, ".gltf"),
    "save_binvox": _save(2048, ".binvox", fill=True),
    "save_vox": _save(2048, ".vox"),
    "save_vdb": _save(1024, ".vdb"),
    "save_npz": _save(768, ".npz"),
    "save_html": _save(256, ".html"),
}


def interrupt_at(call, delay):
    """Runs call() with SIGINT sent `delay` seconds in: ("interrupted", seconds from the signal to the
    KeyboardInterrupt), or ("finished", seconds the call took) when it ended first."""
    sent = {}

    def fire():
        sent["t"] = time.monotonic()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(delay, fire)
    start = time.monotonic()
    try:
        timer.start()
        call()
        took = time.monotonic() - start
        timer.cancel()
        timer.join()
        time.sleep(0.05)  # a signal sent as the call ended lands here
        return "finished", took
    except KeyboardInterrupt:
        return "interrupted", time.monotonic() - sent["t"]


def run(case, moments, bunny):
    """The JSON report of a case: {"length": s, "results": [[what, seconds, at], ...], "left": [...]}."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        call, out = CASES[case](folder, bunny)
        start = time.monotonic()
        call()
        length = time.monotonic() - start
        before = sorted(os.listdir(folder))
        old = out.read_bytes() if out else None
        results = []
        for at in moments:
            what, seconds = interrupt_at(call, at * length)
            results.append([what, seconds, at * length])
        left = sorted(set(os.listdir(folder)) ^ set(before))
        kept = out is None or out.read_bytes() == old
        alive = libvox.voxelize((np.eye(3), np.array([[0, 1, 2]])), resolution=4).occupied_count > 0
    return {"case": case, "length": length, "results": results, "changed_files": left, "old_output_kept": kept,
            "alive": alive}


if __name__ == "__main__":
    name, moments = sys.argv[1], [float(m) for m in sys.argv[2].split(",")]
    print(json.dumps(run(name, moments, sys.argv[3] if len(sys.argv) > 3 else None)))
