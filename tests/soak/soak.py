#!/usr/bin/env python3
"""Soak test: random scenes through vox-voxelize, vox-trace and vox-export, with the tools' invariants checked.

Usage: soak.py BUILD_DIR COUNT [--seed S] [--jobs J] [--keep DIR]

Scene i is drawn from its own generator (seed, i), so any failure replays alone. Each scene is an OBJ or ASCII PLY
triangle soup, or a course text scene of spheres, ellipsoids, triangles and sometimes a plane, at a random size
and offset (1e-6 to 1e7), with degenerate triangles (collinear, repeated points, one point thrice) among the rest:
- voxelized with --grid (1x1x1, thin, up to 24 a side) or --res (1 to 32), --method exact, sat or bbox, and now
  and then --bounds cutting the scene or --fill;
- traced at 48x48 (now and then another size, or a camera inside the bounds) in shade, normals or depth mode with
  --accel grid and --accel none: the two float images (.exr) must be equal byte for byte but for the header's
  time stamp (DESIGN.md: identical images for exact, sat and bbox grids, for every ray of every bounce);
- exported with --faces exposed and merged as ASCII PLY: every edge used exactly once in each direction (closed
  and consistently oriented) and the faces around every vertex one fan (2-manifold);
- every tool exits 0, or 2 with a one-line message; never a signal, another code or a hang.
A failing scene is copied to --keep (default BUILD_DIR/soak-failures) with the commands that failed.
"""
import argparse
import collections
import concurrent.futures
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

TIMEOUT_SECONDS = 300
TIME_STAMP = re.compile(rb"\d{4}:\d\d:\d\d \d\d:\d\d:\d\d")


def num(x):
    return repr(float(x))


def vec(v):
    return " ".join(num(c) for c in v)


class Frame:
    """Where a scene lives: an offset of magnitude 1e-6 to 1e7 and a size that stays well above its rounding."""

    def __init__(self, rng):
        magnitude = 10 ** rng.uniform(-6, 7)
        self.offset = [magnitude * rng.uniform(-1, 1) for _ in range(3)]
        self.size = max(10 ** rng.uniform(-3, 3), magnitude * 1e-9)

    def point(self, rng):
        return [o + self.size * rng.uniform(-1, 1) for o in self.offset]


def triangle(rng, frame):
    """A triangle, degenerate one time in four."""
    a, b, c = frame.point(rng), frame.point(rng), frame.point(rng)
    kind = rng.random()
    if kind < 0.08:  # collinear
        t = rng.uniform(-1, 2)
        c = [a[i] + t * (b[i] - a[i]) for i in range(3)]
    elif kind < 0.16:  # a repeated point
        c = list(a) if rng.random() < 0.5 else list(b)
    elif kind < 0.2:  # one point thrice
        b, c = list(a), list(a)
    elif kind < 0.25:  # a sliver
        c = [a[i] + 0.5 * (b[i] - a[i]) + frame.size * 1e-9 * rng.uniform(-1, 1) for i in range(3)]
    elif kind < 0.35:  # on a lattice: faces, edges and corners that meet cell boundaries
        step = frame.size / rng.choice([1, 2, 4, 8])
        a, b, c = ([o + step * rng.randint(-4, 4) for o in frame.offset] for _ in range(3))
    return a, b, c


def write_obj(rng, frame, path):
    lines, count = [], 0
    for _ in range(rng.choice([1, 2, 5, 12, 40])):
        tri = triangle(rng, frame)
        lines += ["v " + vec(p) for p in tri]
        count += 3
        lines.append("f %d %d %d" % (count - 2, count - 1, count) if rng.random() < 0.8 else "f -3 -2 -1")
    if rng.random() < 0.3:  # a quad
        lines += ["v " + vec(frame.point(rng)) for _ in range(4)]
        lines.append("f -4 -3 -2 -1")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_ply(rng, frame, path):
    tris = [triangle(rng, frame) for _ in range(rng.choice([1, 3, 10, 30]))]
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                "property double z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                % (3 * len(tris), len(tris)))
        for tri in tris:
            for p in tri:
                f.write(vec(p) + "\n")
        for i in range(len(tris)):
            f.write("3 %d %d %d\n" % (3 * i, 3 * i + 1, 3 * i + 2))


def write_course(rng, frame, path):
    """Spheres from tiny to huge, ellipsoids, triangles, sometimes a plane; Phong materials with reflection and
    refraction, directional and point lights, a perspective or orthographic camera framing the scene."""
    s, o = frame.size, frame.offset
    objects = []
    for _ in range(rng.choice([1, 2, 4, 8])):
        material = "MaterialIndex %d" % rng.randint(0, 2)
        kind = rng.random()
        if kind < 0.45:
            radius = max(s * 10 ** rng.uniform(-5, 1.5), max(map(abs, o)) * 1e-9, 1e-300)
            objects.append((material, "Sphere { center %s radius %s }" % (vec(frame.point(rng)), num(radius))))
        elif kind < 0.65:
            ops = "Translate %s Scale %s %s %s %s %s" % (
                vec(frame.point(rng)), num(s * rng.uniform(0.05, 1)), num(s * rng.uniform(0.05, 1)),
                num(s * rng.uniform(0.05, 1)), rng.choice(["XRotate", "YRotate", "ZRotate"]),
                num(rng.uniform(-180, 180)))
            objects.append((material, "Transform { %s Sphere { center 0 0 0 radius 1 } }" % ops))
        else:
            a, b, c = triangle(rng, frame)
            objects.append((material, "Triangle { vertex0 %s vertex1 %s vertex2 %s }" % (vec(a), vec(b), vec(c))))
    if rng.random() < 0.15:
        n = [rng.gauss(0, 1) for _ in range(3)]
        length = math.sqrt(sum(c * c for c in n)) or 1
        n = [c / length for c in n]
        d = sum(n[i] * o[i] for i in range(3)) - s * rng.uniform(1, 3)
        objects.append(("MaterialIndex 0", "Plane { normal %s offset %s }" % (vec(n), num(d))))
    eye = [o[i] + s * 4 * d for i, d in enumerate([rng.uniform(-1, 1), rng.uniform(-1, 1), 1])]
    direction = [o[i] - eye[i] for i in range(3)]
    if rng.random() < 0.5:
        camera = "PerspectiveCamera { center %s direction %s up 0 1 0 angle %s }" % (
            vec(eye), vec(direction), num(rng.uniform(20, 60)))
    else:
        camera = "OrthographicCamera { center %s direction %s up 0 1 0 size %s }" % (
            vec(eye), vec(direction), num(s * rng.uniform(2, 5)))
    with open(path, "w") as f:
        f.write(camera + "\n")
        f.write("Lights { numLights 2\n  DirectionalLight { direction %s color 0.7 0.7 0.7 }\n"
                "  PointLight { position %s color 0.5 0.5 0.5 attenuation 1 0 0 } }\n"
                % (vec([rng.uniform(-1, 1), -1, rng.uniform(-1, -0.1)]), vec(eye)))
        f.write("Background { color 0.1 0.2 0.3 ambientLight 0.1 0.1 0.1 }\n")
        f.write("Materials { numMaterials 3\n  Material { diffuseColor 0.9 0.2 0.2 }\n"
                "  PhongMaterial { diffuseColor 0.2 0.8 0.2 specularColor 1 1 1 exponent 30 "
                "reflectiveColor 0.5 0.5 0.5 }\n"
                "  PhongMaterial { diffuseColor 0.1 0.1 0.3 transparentColor 0.7 0.7 0.7 indexOfRefraction 1.5 }\n}\n")
        f.write("Group { numObjects %d\n" % len(objects))
        for material, text in objects:
            f.write("  %s\n  %s\n" % (material, text))
        f.write("}\n")


def voxelize_options(rng, frame):
    grid = rng.random()
    if grid < 0.1:
        opts = ["--grid", "1", "1", "1"]
    elif grid < 0.35:  # thin: one or two axes of one cell
        dims = [rng.randint(1, 32) for _ in range(3)]
        for axis in rng.sample(range(3), rng.choice([1, 2])):
            dims[axis] = 1
        opts = ["--grid"] + [str(d) for d in dims]
    elif grid < 0.7:
        opts = ["--grid"] + [str(rng.randint(1, 24)) for _ in range(3)]
    else:
        opts = ["--res", str(rng.randint(1, 32))]
    opts += ["--method", rng.choice(["exact", "sat", "bbox"])]
    if rng.random() < 0.1:  # bounds that cut the scene: primitives stick out and are traced apart
        lo = [o - frame.size * rng.uniform(0.2, 1.2) for o in frame.offset]
        hi = [o + frame.size * rng.uniform(0.2, 1.2) for o in frame.offset]
        opts += ["--bounds"] + [num(c) for c in lo + hi]
    if rng.random() < 0.1:
        opts.append("--fill")
    return opts


def trace_options(rng, frame):
    opts = ["--mode", rng.choice(["shade", "normals", "depth"])]
    size = rng.choice([(48, 48)] * 6 + [(1, 1), (7, 48), (48, 5)])
    opts += ["--size", str(size[0]), str(size[1])]
    if rng.random() < 0.25:  # a camera anywhere near the scene, often inside the grid
        eye, look = frame.point(rng), frame.point(rng)
        if eye != look:
            opts += ["--eye"] + [num(c) for c in eye] + ["--look-at"] + [num(c) for c in look]
    return opts


def image_bytes(path):
    """The file's bytes without the time stamp that OpenImageIO writes into EXR headers (capDate)."""
    with open(path, "rb") as f:
        return TIME_STAMP.sub(b"", f.read())


def check_closed_manifold(path):
    """Returns None for a closed, consistently oriented, 2-manifold ASCII PLY mesh, else what is wrong."""
    with open(path) as f:
        lines = f.read().split("\n")
    if lines[1] != "format ascii 1.0":
        return "not an ASCII PLY"
    end = lines.index("end_header")
    counts = {}
    for line in lines[:end]:
        words = line.split()
        if words[:1] == ["element"]:
            counts[words[1]] = int(words[2])
    start = end + 1 + counts.get("vertex", 0)
    directed = collections.Counter()
    fans = collections.defaultdict(dict)
    for line in lines[start:start + counts.get("face", 0)]:
        words = line.split()
        face = [int(w) for w in words[1:1 + int(words[0])]]
        if len(set(face)) != len(face):
            return "face %s repeats a vertex" % face
        for i, v in enumerate(face):
            directed[(v, face[(i + 1) % len(face)])] += 1
            fans[v][face[i - 1]] = face[(i + 1) % len(face)]
    for (a, b), n in directed.items():
        if n != 1:
            return "edge %d->%d used %d times" % (a, b, n)
        if directed.get((b, a)) != 1:
            return "edge %d-%d is a boundary or inconsistently oriented" % (a, b)
    for v, fan in fans.items():  # around v, the corner with previous vertex p leads to the one with previous fan[p]
        first = next(iter(fan))
        at, steps = fan[first], 1
        while at != first and steps <= len(fan):
            at, steps = fan[at], steps + 1
        if steps != len(fan):
            return "vertex %d: its %d faces form more than one fan" % (v, len(fan))
    return None


class Soak:
    def __init__(self, build, seed, keep):
        self.build, self.seed, self.keep = build, seed, keep

    def run(self, tool, args, log):
        """Runs a tool; returns its exit code after checking it is 0, or 2 with one line (else raises)."""
        command = [os.path.join(self.build, tool)] + args + ["--quiet", "--threads", "1"]
        log.append(" ".join(command))
        try:
            done = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=TIMEOUT_SECONDS)
        except subprocess.TimeoutExpired:
            raise AssertionError("%s: no answer after %d s" % (tool, TIMEOUT_SECONDS))
        err = done.stderr
        if done.returncode == 0:
            return 0
        if done.returncode == 2 and err.count("\n") == 1 and err.startswith(tool + ": error: "):
            return 2
        raise AssertionError("%s: exit %d, stderr: %s" % (tool, done.returncode, err[:500]))

    def scene(self, index):
        """Runs scene `index`; returns (refused, None) or (None, failure message)."""
        rng = random.Random(self.seed * 1000003 + index)
        frame = Frame(rng)
        folder = tempfile.mkdtemp(prefix="soak%d-" % index)
        log = []
        try:
            kind = rng.choice(["obj", "ply", "txt", "txt"])
            scene = os.path.join(folder, "scene." + kind)
            {"obj": write_obj, "ply": write_ply, "txt": write_course}[kind](rng, frame, scene)
            grid = os.path.join(folder, "g.vgrid")
            if self.run("vox-voxelize", [scene, "-o", grid] + voxelize_options(rng, frame), log) == 2:
                return True, None
            trace = trace_options(rng, frame)
            images = []
            for accel in ["grid", "none"]:
                images.append(os.path.join(folder, accel + ".exr"))
                if self.run("vox-trace", [grid, "-o", images[-1], "--accel", accel] + trace, log) == 2:
                    raise AssertionError("vox-trace refused a grid vox-voxelize wrote")
            if image_bytes(images[0]) != image_bytes(images[1]):
                raise AssertionError("--accel grid and --accel none images differ")
            for faces in ["exposed", "merged"]:
                mesh = os.path.join(folder, faces + ".ply")
                if self.run("vox-export", [grid, "-o", mesh, "--faces", faces, "--ascii", "--color", "none"], log):
                    raise AssertionError("vox-export refused a grid vox-voxelize wrote")
                problem = check_closed_manifold(mesh)
                if problem:
                    raise AssertionError("--faces %s: %s" % (faces, problem))
            return False, None
        except AssertionError as e:
            kept = os.path.join(self.keep, "scene%d" % index)
            shutil.rmtree(kept, ignore_errors=True)
            shutil.copytree(folder, kept)
            with open(os.path.join(kept, "commands.txt"), "w") as f:
                f.write("\n".join(log) + "\n")
            return None, "scene %d (%s): %s\n  last command: %s" % (index, kept, e, log[-1] if log else "")
        finally:
            shutil.rmtree(folder, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build")
    parser.add_argument("count", type=int)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--keep")
    args = parser.parse_args()
    keep = args.keep or os.path.join(args.build, "soak-failures")
    soak = Soak(args.build, args.seed, keep)
    start = time.monotonic()
    refused, failures = 0, []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for was_refused, failure in pool.map(soak.scene, range(args.count)):
            refused += bool(was_refused)
            if failure:
                failures.append(failure)
                print("FAIL:", failure, flush=True)
    print("soak: %d scenes, %d refused by vox-voxelize (exit 2), %d failed, %.1f s"
          % (args.count, refused, len(failures), time.monotonic() - start))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
