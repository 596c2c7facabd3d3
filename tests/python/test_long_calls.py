"""Long calls: Ctrl-C stops them within half a second, the GIL is released (two Python threads voxelize at once),
progress is reported, voxelize_batch spreads meshes over threads, and 1,000 calls do not leak."""

import gc
import os
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import libvox
from conftest import BUNNY_PLY, SCENES, assert_same_grid, read_ascii_ply

# SIGINT at ten moments of call(), moment i at length * spread(i) seconds into it; prints "interrupted LATENCY" or
# "finished" for each. Prepended to the scripts below, each run in its own Python.
TEN_MOMENTS = textwrap.dedent("""
    import os, signal, threading, time

    def interrupt_ten_times(call, length, spread):
        for i in range(10):
            sent = {}
            def fire():
                sent["t"] = time.monotonic()
                os.kill(os.getpid(), signal.SIGINT)
            timer = threading.Timer(length * spread(i), fire)
            try:
                timer.start()
                call()
                timer.cancel()
                timer.join()
                time.sleep(0.05)  # a signal sent as the call ended lands here
                print("finished")
            except KeyboardInterrupt:
                print("interrupted", time.monotonic() - sent["t"])
""")


def assert_interrupted_quickly(script, what, at_least=8):
    """Runs a moments script for `what` on the bunny: at least `at_least` of the 10 moments interrupted (a late one
    may come after the call finished), each within 0.5 s, and the module alive afterwards."""
    proc = subprocess.run([sys.executable, "-c", TEN_MOMENTS + script, what, str(BUNNY_PLY)], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.split("\n")
    assert lines[0].startswith("length") and lines[-2] == "alive", proc.stdout
    latencies = [float(l.split()[1]) for l in lines if l.startswith("interrupted")]
    assert len(latencies) >= at_least, proc.stdout
    assert max(latencies) < 0.5, proc.stdout


# Ctrl-C at ten moments of one call, spread over its length (measured first, uninterrupted): each must raise
# KeyboardInterrupt within half a second of the signal (DESIGN.md "Python"). Prints the latencies, one a line.
MOMENTS = textwrap.dedent("""
    import os, signal, sys, threading, time
    import numpy as np
    import libvox
    # Python turns SIGINT into KeyboardInterrupt only when its parent left SIGINT alone; a job started in the
    # background by a non-interactive shell (as a CI runner may start us) inherits it ignored.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    what, path = sys.argv[1], sys.argv[2]
    with open(path) as f:  # the bunny as arrays, for the batch
        counts = [int(l.split()[2]) for l in iter(f.readline, "end_header\\n") if l.startswith("element")]
        V = np.loadtxt(f, max_rows=counts[0], usecols=(0, 1, 2))
        F = np.loadtxt(f, max_rows=counts[1], usecols=(1, 2, 3), dtype=np.int64)
    grid = libvox.voxelize(path, resolution=64)
    libvox.render(grid, size=(4, 4))  # the trace structure, built on the first render, outside the clock
    lo, hi = np.array(grid.bounds[0]), np.array(grid.bounds[1])
    points = np.random.default_rng(1).uniform(lo, hi, size=(300_000, 3))

    def call():
        if what == "voxelize":
            libvox.voxelize(path, resolution=2048)
        elif what == "fill":  # the fill's serial phases: its row table, flood links and run groups
            libvox.voxelize(path, resolution=1024, fill=True)
        elif what == "batch":
            libvox.voxelize_batch([(V, F)] * 64, 256)
        elif what == "sdf":  # the dense signed distance field's rows
            libvox.sdf(path, resolution=64)
        elif what == "distance":  # nearest primitives of 300,000 points, signed
            grid.distance(points)
        else:
            libvox.render(grid, size=(2000, 2000), samples=16)

    start = time.monotonic()
    if what == "batch":  # its length from an eighth of it: the whole costs seconds the test's budget has not
        libvox.voxelize_batch([(V, F)] * 8, 256)
        length = 8 * (time.monotonic() - start)
    else:
        call()
        length = time.monotonic() - start
    print("length", length)
    # More moments early than late: a call often ends faster than the first (cold) one did.
    interrupt_ten_times(call, length, lambda i: 0.02 + 0.73 * (i / 9) ** 2)
    # The module works after the interrupts.
    assert libvox.voxelize(path, resolution=8).occupied_count > 0
    print("alive")
""")


@pytest.mark.parametrize("what", ["voxelize", "fill", "batch", "sdf", "distance"])
def test_ctrl_c_within_half_a_second(what):
    """voxelize of the bunny at 2048^3, with fill at 1024^3, voxelize_batch of 64 bunnies at 256^3, libvox.sdf of
    the bunny at 64^3 and Grid.distance of 300,000 points, each interrupted at 10 moments."""
    assert_interrupted_quickly(MOMENTS, what)


# Ctrl-C at ten moments of Grid.mesh() on the bunny at 512^3 or Grid.colors() at 1024^3 (about 1.5 s and 0.25 s on
# the 2-core machine; colors() at 512^3 is over in 0.06 s), then the grid, untouched by the cancelled calls, gives the
# same arrays as before.
GRID_MOMENTS = textwrap.dedent("""
    import os, signal, sys, threading, time
    import numpy as np
    import libvox
    signal.signal(signal.SIGINT, signal.default_int_handler)
    what, path = sys.argv[1], sys.argv[2]
    grid = libvox.voxelize(path, resolution=512 if what == "mesh" else 1024)

    def call():
        return grid.mesh(color="count") if what == "mesh" else grid.colors()

    first = call()  # the first call is the slowest (fresh pages): the moments are spread over a second one
    start = time.monotonic()
    call()
    length = time.monotonic() - start
    print("length", length)
    # Early moments weigh more: under load the later calls often run faster than the one measured.
    interrupt_ten_times(call, length, lambda i: 0.02 + 0.6 * (i / 9) ** 2)
    again = call()
    for a, b in zip(first if what == "mesh" else [first], again if what == "mesh" else [again]):
        assert np.array_equal(a, b)
    print("alive")
""")


@pytest.mark.parametrize("what", ["mesh", "colors"])
def test_ctrl_c_grid_mesh_and_colors(what):
    """Grid.mesh() and Grid.colors() of the bunny, each interrupted at 10 moments; the grid works after."""
    # colors() lasts a quarter of a second: on a loaded machine a late moment can miss a call that ran faster.
    assert_interrupted_quickly(GRID_MOMENTS, what, 8 if what == "mesh" else 6)


INTERRUPT = textwrap.dedent("""
    import os, signal, sys, threading, time
    import libvox
    signal.signal(signal.SIGINT, signal.default_int_handler)
    # Reading a scene file and building the trace structure (the first ray call on a grid) are done before the
    # clock starts, so that what is measured is the render's own loop.
    grid = libvox.voxelize(sys.argv[1], resolution=64)
    libvox.render(grid, size=(4, 4))
    sent = {}
    def fire():
        sent["t"] = time.monotonic()
        os.kill(os.getpid(), signal.SIGINT)
    threading.Timer(0.2, fire).start()
    start = time.monotonic()
    try:
        libvox.render(grid, size=(2000, 2000), samples=16)
        print("finished", time.monotonic() - start)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - sent["t"])
    assert libvox.voxelize(sys.argv[1], resolution=8).occupied_count > 0
    print("alive")
""")


def test_ctrl_c_render():
    proc = subprocess.run([sys.executable, "-c", INTERRUPT, str(BUNNY_PLY)], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    words = proc.stdout.split()
    assert words[0] == "interrupted", proc.stdout  # the work takes seconds: it must not have finished
    assert float(words[1]) < 0.5
    assert words[2] == "alive"


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
