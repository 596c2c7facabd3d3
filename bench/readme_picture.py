#!/usr/bin/env python3
"""Makes the README's picture, docs/images/hero.png: the course's 40k bunny (scene6_07) voxelized at its handout grid
of 40x40x33, rendered by vox-trace shaded (shadows, the scene's lights) and as its voxels, side by side.

Usage: bench/readme_picture.py [--build DIR]     (needs Debian's python3-matplotlib; a second of CPU)
"""
import argparse
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SEED = os.environ.get("VOX_SEED_DIR", os.path.join(ROOT, "data"))
OUT = os.path.join(ROOT, "docs", "images", "hero.png")
SIZE = 400


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    scene = os.path.join(SEED, "6837", "scenes", "scene6_07_bunny_mesh_40k.txt")
    with tempfile.TemporaryDirectory() as tmp:
        grid = os.path.join(tmp, "bunny.vgrid")
        tool = lambda name, *a: subprocess.run([os.path.join(args.build, name), *a, "--quiet"], check=True)
        tool("vox-voxelize", scene, "-o", grid, "--grid", "40", "40", "33")
        size = ["--size", str(SIZE), str(SIZE)]
        tool("vox-trace", grid, "-o", os.path.join(tmp, "shade.png"), *size, "--mode", "shade")
        tool("vox-trace", grid, "-o", os.path.join(tmp, "voxels.png"), *size, "--mode", "voxels")
        images = [mpimg.imread(os.path.join(tmp, n))[..., :3] for n in ("shade.png", "voxels.png")]
    captions = ["vox-trace --mode shade (grid 40x40x33)", "vox-trace --mode voxels (grid 40x40x33)"]
    gap, caption = 8, 26  # pixels
    width, height = 2 * SIZE + gap, SIZE + caption
    fig = plt.figure(figsize=(width / 100, height / 100), dpi=100)
    for i, (image, text) in enumerate(zip(images, captions)):
        left = i * (SIZE + gap) / width
        ax = fig.add_axes((left, caption / height, SIZE / width, SIZE / height))
        ax.imshow(image, interpolation="nearest")
        ax.set_axis_off()
        fig.text(left + SIZE / width / 2, caption / height / 2, text, ha="center", va="center", fontsize=9,
                 family="monospace")
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    fig.savefig(OUT, dpi=100)
    print(f"wrote {OUT} ({os.path.getsize(OUT) // 1024} KB)")


if __name__ == "__main__":
    sys.exit(main())
