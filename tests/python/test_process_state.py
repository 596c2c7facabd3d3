"""A library call leaves the process as it found it (issue 45, defect 2): after any Grid.save, in any thread, Ctrl-C
raises KeyboardInterrupt (the library's own SIGINT handler, which ended the interpreter with status 130, stayed
installed); the signal dispositions at the C level and as Python sees them, the locale and the floating-point
environment are the same after voxelize, sdf, save (every format), load, render, distance, mesh and the rays.

Each case runs in a child interpreter, so that a failure (the process ending on SIGINT) cannot take pytest with it."""

import subprocess
import sys
import textwrap

import pytest

# Every format family Grid.save writes: the grid file, a grid set (a temporary folder), meshes, voxel formats, the
# viewer page (skipped by the child when the build has none).
SAVES = ["g.vgrid", "set.vgrid:bricks", "m.ply", "m.obj", "m.off", "m.stl", "m.glb", "m.gltf", "v.binvox", "v.vox",
         "v.vdb", "p.html"]

PRELUDE = textwrap.dedent("""
    import ctypes, locale, os, signal, sys, tempfile, threading, time
    import numpy as np
    import libvox

    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    folder = tempfile.mkdtemp()

    def save(grid, name):
        path, _, bricks = name.partition(":")
        try:
            if bricks and grid.sdf_half_width > 0:  # a grid set holds no distances: the band's grid refuses it
                grid = libvox.voxelize((V, F), resolution=8, fill=True)
            grid.save(os.path.join(folder, path), **({"bricks": 2} if bricks else {}))
            return True
        except libvox.UsageError as e:
            if name.endswith(".html") and "viewer" in str(e):
                return False  # a build without the viewer page
            raise
""")

CTRL_C = PRELUDE + textwrap.dedent("""
    grid = libvox.voxelize((V, F), resolution=8, fill=True)
    threaded = sys.argv[1] == "thread"
    for name in sys.argv[2:]:
        if threaded:
            done = []
            worker = threading.Thread(target=lambda: done.append(save(grid, name)))
            worker.start()
            worker.join()
            written = done[0]
        else:
            written = save(grid, name)
        try:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(100):  # Python's handler raises at the next bytecode; the library's ended the process
                time.sleep(0.01)
            print("no KeyboardInterrupt after", name, flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt after", name if written else "(not built) " + name, flush=True)
""")


def run(script, *args):
    return subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("where", ["main", "thread"])
def test_ctrl_c_raises_keyboard_interrupt_after_every_save(where):
    proc = run(CTRL_C, where, *SAVES)
    assert proc.returncode == 0, f"exit {proc.returncode} (130: ended by the library's SIGINT handler)\n" \
                                 f"{proc.stdout}{proc.stderr}"
    lines = proc.stdout.splitlines()
    assert len(lines) == len(SAVES), proc.stdout
    for line, name in zip(lines, SAVES):
        assert line.startswith("KeyboardInterrupt after") and line.endswith(name), proc.stdout


# Ctrl-C while a save is under way: Python's handler stays in place, so KeyboardInterrupt is raised (during the
# save or right after it) and the process lives on; the output is the old file or the whole new one, and no
# temporary file is left.
DURING = PRELUDE + textwrap.dedent("""
    import pickle
    small = libvox.voxelize((V, F), resolution=4)
    big = libvox.voxelize(sys.argv[1], resolution=192, fill=True)
    for name in sys.argv[2:]:
        path = os.path.join(folder, name)
        small.save(path)
        old = open(path, "rb").read()
        finished, seen = threading.Event(), []

        def watch():  # Ctrl-C once the temporary file exists (or, at the latest, once the save is over)
            while not finished.is_set() and not any(".tmp" in f for f in os.listdir(folder)):
                time.sleep(0.001)
            seen.append(not finished.is_set())
            os.kill(os.getpid(), signal.SIGINT)

        watcher = threading.Thread(target=watch)
        watcher.start()
        try:
            try:
                big.save(path)
            finally:
                finished.set()
            watcher.join()
            time.sleep(2)
            print("no KeyboardInterrupt", name)
        except KeyboardInterrupt:
            watcher.join()
        new = open(path, "rb").read()
        if name.endswith(".vgrid"):
            assert new == old or libvox.load(path).__getstate__()[0] == big.__getstate__()[0], name
        else:
            assert new == old or len(new) > len(old), name
        left = [f for f in os.listdir(folder) if ".tmp" in f]
        assert not left, left
        print("ok", name, "old" if new == old else "new", "during" if seen[0] else "after", flush=True)
""")


def test_ctrl_c_during_a_save_keeps_the_old_output_or_the_whole_new_one():
    from conftest import BUNNY_PLY
    names = ["g.vgrid", "m.ply", "v.vdb"]
    proc = run(DURING, str(BUNNY_PLY), *names)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}{proc.stderr}"
    assert [line.split()[:2] for line in proc.stdout.splitlines()] == [["ok", n] for n in names], proc.stdout


# The process state a library could change: signal dispositions (as Python reports them, and the C-level ones, which
# Python does not see: the library's handler hid behind Python's own table), the locale, the floating-point
# rounding, enabled traps and, on x86-64, the x87 control word and the MXCSR control bits (flush-to-zero,
# denormals-are-zero, as -ffast-math code sets them).
STATE = PRELUDE + textwrap.dedent("""
    import platform
    libc = ctypes.CDLL(None, use_errno=True)
    SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGXFSZ, signal.SIGPIPE, signal.SIGUSR1]

    def c_disposition(sig):
        action = ctypes.create_string_buffer(256)  # struct sigaction, with room to spare
        assert libc.sigaction(sig, None, action) == 0
        flags = int.from_bytes(action.raw[8 + 128:8 + 128 + 4], "little") & ~0x04000000  # SA_RESTORER: glibc's own
        return action.raw[:8].hex(), hex(flags)  # the handler and the flags

    def fp_state():
        state = [libc.fegetround(), libc.fegetexcept()]
        if platform.machine() == "x86_64":
            env = ctypes.create_string_buffer(64)
            assert libc.fegetenv(env) == 0
            state += [env.raw[0:2], int.from_bytes(env.raw[24:28], "little") & ~0x3F]  # x87 control, MXCSR control
        return state

    def snapshot():
        return {"locale": locale.setlocale(locale.LC_ALL),
                "python signals": [signal.getsignal(s) for s in SIGNALS],
                "C signals": [c_disposition(s) for s in SIGNALS],
                "fp": fp_state()}

    locale.setlocale(locale.LC_ALL, "C.UTF-8")  # not the "C" locale a library might set back
    signal.signal(signal.SIGUSR1, lambda *a: None)
    before = snapshot()
    grid = libvox.voxelize((V, F), resolution=8, fill=True, sdf=2)
    calls = {
        "voxelize": lambda: libvox.voxelize((V, F), resolution=8, fraction=True),
        "voxelize_batch": lambda: libvox.voxelize_batch([(V, F)], resolution=8),
        "sdf": lambda: libvox.sdf((V, F), resolution=8),
        "load": lambda: libvox.load(os.path.join(folder, "g.vgrid")),
        "render": lambda: libvox.render(grid, size=(16, 16)),
        "save_image": lambda: libvox.save_image(os.path.join(folder, "i.png"), libvox.render(grid, size=(8, 8))),
        "distance": lambda: grid.distance([[0.2, 0.2, 0.2], [2, 2, 2]]),
        "mesh": lambda: grid.mesh(),
        "intersect": lambda: grid.intersect([[-1, 0.2, 0.2]], [[1, 0, 0]]),
        "pickle": lambda: __import__("pickle").loads(__import__("pickle").dumps(grid)),
    }
    for name in sys.argv[1:]:
        calls["save " + name] = (lambda n: lambda: save(grid, n))(name)
    save(grid, "g.vgrid")
    for name, call in calls.items():
        call()
        after = snapshot()
        for key in before:
            if after[key] != before[key]:
                print("changed by", name + ":", key, before[key], "->", after[key])
    print("checked", len(calls))
""")


def test_process_state_is_left_as_found():
    proc = run(STATE, *SAVES)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}{proc.stderr}"
    assert proc.stdout.strip() == f"checked {10 + len(SAVES)}", proc.stdout
