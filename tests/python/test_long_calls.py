"""Long calls: Ctrl-C stops every one of them (long_calls.py), the GIL is released (two Python threads voxelize at once),
progress is reported, voxelize_batch spreads meshes over threads, and 1,000 calls do not leak."""

import gc
import json
import os
import pathlib
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import libvox
from conftest import BUNNY_PLY, SCENES, assert_same_grid, read_ascii_ply
from long_calls import CASES

# Ctrl-C in every call that can take longer than half a second (long_calls.py CASES): each case is sized to take
# seconds, run once uninterrupted (its length), then once with SIGINT sent a quarter into it. The wall-clock limits
# are wide, so that a loaded 2-core machine cannot fail them: the KeyboardInterrupt within 2 s of the signal, and the
# call back well before its length (a call that ignored the signal until its end would come back at about its
# length). The 0.5 s promise is measured by bench/python_ctrl_c.py (docs/python.md).
LATENCY_LIMIT = 2.0

# Calls without cancellation yet.
NOT_YET = {
    "save_gltf": "tinygltf builds the .gltf (its buffer base64-encoded) in one call: 2.7 s past Ctrl-C",
    "save_glb": "tinygltf writes the .glb in one call: up to 2.3 s past Ctrl-C (bench/python_ctrl_c.py)",
}


def run_case(case, moments):
    proc = subprocess.run([sys.executable, str(pathlib.Path(__file__).with_name("long_calls.py")), case,
                           ",".join(map(str, moments)), str(BUNNY_PLY)], capture_output=True, text=True, timeout=600)
    return proc


@pytest.fixture(scope="module")
def case_reports(request):
    """The selected cases run two at a time (each a process of its own, whose SIGINT reaches only it): 35 cases of a
    few seconds each, which one at a time took 12 minutes of the test command. The 2 s allowance holds with the
    other process busy (docs/python.md)."""
    selected = [item.callspec.params["case"] for item in request.session.items
                if item.originalname == "test_ctrl_c_stops_long_call" and hasattr(item, "callspec")]
    pool = ThreadPoolExecutor(max_workers=2)
    futures = {case: pool.submit(run_case, case, [0.25]) for case in selected}
    yield futures
    pool.shutdown(cancel_futures=True)


# Not strict: whether the one unchecked call of such a case outlasts the allowance depends on where the signal lands
# (save_gltf passed once in three runs, save_glb failed once in four); bench/python_ctrl_c.py measures it.
@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.xfail(reason=NOT_YET[c], strict=False))
                                  if c in NOT_YET else c for c in CASES])
def test_ctrl_c_stops_long_call(case, case_reports):
    """KeyboardInterrupt, well inside 2 s, from a call that would have run on for seconds; no temporary file left,
    a save's old output byte for byte, the module working afterwards."""
    proc = case_reports[case].result() if case in case_reports else run_case(case, [0.25])
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.splitlines()[-1])
    (what, seconds, sent_at), = report["results"]
    assert what == "interrupted", report  # a call that finished first was too short to test anything
    assert seconds < LATENCY_LIMIT, report
    assert sent_at + seconds < 0.7 * report["length"], report  # it stopped, rather than ran to its end
    assert report["changed_files"] == [] and report["old_output_kept"] and report["alive"], report


def test_two_threads_voxelize_at_once():
    """Both calls run inside the library at the same time: the second starts before the first ends, and the main
    thread runs Python meanwhile."""
    spans = {}

    def work(name):
        start = time.monotonic()
        libvox.voxelize(BUNNY_PLY, resolution=512, threads=1)
        spans[name] = (start, time.monotonic())

    threads = [threading.Thread(target=work, args=(n,)) for n in ("a", "b")]
    for t in threads:
        t.start()
    ticks = 0
    while any(t.is_alive() for t in threads):
        ticks += 1
        time.sleep(0.001)
    (a0, a1), (b0, b1) = spans["a"], spans["b"]
    assert max(a0, b0) < min(a1, b1)  # the intervals overlap
    overlap = min(a1, b1) - max(a0, b0)
    assert overlap > 0.5 * min(a1 - a0, b1 - b0)
    assert ticks > 50


def test_progress_callback():
    seen = []
    libvox.voxelize(BUNNY_PLY, resolution=256, progress=seen.append)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen)
    with pytest.raises(ZeroDivisionError):
        libvox.voxelize(BUNNY_PLY, resolution=256, progress=lambda f: 1 / 0)
    with pytest.raises(TypeError):
        libvox.voxelize(BUNNY_PLY, resolution=8, progress="yes")
    libvox.voxelize(BUNNY_PLY, resolution=64, progress=True)  # tqdm when installed, else nothing


def small_meshes(count, seed=1):
    """Closed tetrahedra and boxes of random size and place."""
    rng = np.random.default_rng(seed)
    tet_f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    out = []
    for _ in range(count):
        v = rng.normal(size=(4, 3)) * rng.uniform(0.5, 2, size=3) + rng.uniform(-5, 5, size=3)
        out.append((v, tet_f))
    return out


@pytest.mark.filterwarnings("ignore:.*nothing filled")  # tetrahedra wound inwards: the fill finds no inside
def test_batch_equals_voxelize():
    meshes = small_meshes(20) + [(read_ascii_ply(BUNNY_PLY))]
    r = 32
    dense = libvox.voxelize_batch(meshes, r)
    assert dense.shape == (len(meshes), r, r, r) and dense.dtype == np.bool_
    filled = libvox.voxelize_batch(meshes, r, fill=True)
    grids = libvox.voxelize_batch(meshes, r, dense=False)
    for b, (v, f) in enumerate(meshes):
        lo, hi = v.min(axis=0), v.max(axis=0)
        longest = np.argmax(hi - lo)
        side = (hi - lo)[longest]
        mid = (lo + hi) / 2
        cube_lo = np.minimum(lo, mid - side / 2)
        cube_hi = np.maximum(hi, mid + side / 2)
        cube_lo[longest], cube_hi[longest] = lo[longest], hi[longest]
        one = libvox.voxelize((v, f), dims=r, bounds=(cube_lo, cube_hi))
        assert np.array_equal(dense[b], one.dense()), b
        assert_same_grid(grids[b], one)
        assert np.array_equal(filled[b], libvox.voxelize((v, f), dims=r, bounds=(cube_lo, cube_hi), fill=True).dense())
    assert filled.sum() > dense.sum()


def idle_seconds():
    """Seconds the machine's cores spent idle so far (all cores together), from /proc/stat."""
    fields = open("/proc/stat").readline().split()
    return (int(fields[4]) + int(fields[5])) / os.sysconf("SC_CLK_TCK")


def test_batch_threads_scale():
    cores = os.cpu_count() or 1
    if cores < 2:
        pytest.skip("one core")
    meshes = small_meshes(300)
    libvox.voxelize_batch(meshes[:10], 64)
    times, idle, sums = {}, {}, {}
    for threads in (1, 2):
        times[threads] = float("inf")
        for _ in range(3):  # the best of three: other jobs may share the cores
            idle0, start = idle_seconds(), time.perf_counter()
            out = libvox.voxelize_batch(meshes, 64, threads=threads)
            wall = time.perf_counter() - start
            if wall < times[threads]:
                times[threads], idle[threads] = wall, (idle_seconds() - idle0) / wall
        sums[threads] = int(out.sum())
    assert sums[1] == sums[2]
    speedup = times[1] / times[2]
    if speedup > 1.3:
        return  # 2 cores shared with other jobs: a clear gain; bench/python_bench.py measures the full one
    # No gain: a failure if a core stood idle meanwhile, else the machine was busy with other work.
    assert idle[2] < 0.3, f"speed-up {speedup:.2f} while {idle[2]:.2f} cores stood idle: {times}"
    pytest.skip(f"speed-up {speedup:.2f}, but no core was free (other jobs): {times}")


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def test_no_leaks():
    meshes = small_meshes(50)
    rays_o = np.tile([0.0, 0.0, -10.0], (200, 1))
    rays_d = np.random.default_rng(2).normal(size=(200, 3))

    def round_of_calls(n):
        for i in range(n):
            v, f = meshes[i % len(meshes)]
            g = libvox.voxelize((v, f), resolution=32)
            t, p, nrm = g.intersect(rays_o, rays_d)
            g.dense(), g.indices, g.points, g.cell_primitives, g.mesh()
        gc.collect()

    round_of_calls(200)  # allocator and caches warm
    before = rss_mb()
    round_of_calls(1000)
    grown = rss_mb() - before
    assert grown < 4, f"RSS grew by {grown:.1f} MB over 1000 calls"


def test_interrupted_then_fine():
    """A call cancelled by its progress callable leaves nothing behind: the same call then gives the same grid."""
    class Stop(Exception):
        pass

    def stop(fraction):
        if fraction > 0:
            raise Stop()

    with pytest.raises(Stop):
        libvox.voxelize(BUNNY_PLY, resolution=400, progress=stop)
    assert_same_grid(libvox.voxelize(SCENES / "teapot.obj", resolution=20),
                     libvox.voxelize(SCENES / "teapot.obj", resolution=20))
