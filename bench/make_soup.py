#!/usr/bin/env python3
"""Writes a triangle soup as OBJ: N triangles, each with its three corners within SIZE/2 of a centre drawn uniformly in
the unit cube (seeded, so the same file every time). A scene where merging empty cells cannot help much (issue 27,
docs/speed.md "Issue 27's goals"):
    python3 bench/make_soup.py /tmp/soup.obj && build/bench/bench_trace --incoherent --size 512 /tmp/soup.obj
"""
import argparse
import random


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", help="the OBJ file to write")
    parser.add_argument("--triangles", type=int, default=100000)
    parser.add_argument("--size", type=float, default=0.02, help="largest extent of a triangle on each axis")
    parser.add_argument("--seed", type=int, default=27)
    args = parser.parse_args()
    random.seed(args.seed)
    half = args.size / 2
    with open(args.out, "w") as f:
        for _ in range(args.triangles):
            c = [random.random() for _ in range(3)]
            for _ in range(3):
                f.write("v %.9f %.9f %.9f\n" % tuple(c[a] + random.uniform(-half, half) for a in range(3)))
        for i in range(args.triangles):
            f.write("f %d %d %d\n" % (3 * i + 1, 3 * i + 2, 3 * i + 3))


if __name__ == "__main__":
    main()
