#!/usr/bin/env python3
"""Independent readers of the voxel files vox-export writes, from the published descriptions only:
  binvox: Patrick Min's page (https://www.patrickmin.com/binvox/binvox.html) and binvox-rw-py's read_as_3d_array
          (header lines, then (value, count) byte pairs over index x*D*D + z*D + y: x slowest, y fastest);
  .vox:   ephtracy/voxel-model, MagicaVoxel-file-format-vox.txt and -vox-extension.txt (RIFF chunks SIZE/XYZI, the
          scene graph nTRN/nGRP/nSHP with "_t" translations, RGBA palette where entry i is colour index i + 1);
          a model's voxel v is at translation + v - size // 2 (MagicaVoxel centres a model on its translation);
  .vdb:   OpenVDB's own Python module (pyopenvdb, Debian's python3-openvdb).
Usage: voxel_readers.py [INFO_JSON] FILE...
Prints one line "RESULT FILE voxels=N ..." per file and writes its cells, one "x y z" a line in sorted order, to
FILE.cells. With INFO_JSON (vox-info --json --cells of the same grid) it checks that the file holds exactly
occupied_cells + solid_cells voxels, every occupied cell among them; exits 1 on any mismatch or malformed file.
"""
import json
import struct
import sys


def read_binvox(path):
    with open(path, "rb") as f:
        data = f.read()
    lines = []
    pos = 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii").strip()
        pos = end + 1
        lines.append(line)
        if line == "data":
            break
    assert lines[0] == "#binvox 1", lines[0]
    header = {l.split()[0]: l.split()[1:] for l in lines[1:-1]}
    dims = [int(x) for x in header["dim"]]
    d = dims[0]
    assert dims == [d, d, d], dims
    body = data[pos:]
    assert len(body) % 2 == 0, "odd number of run bytes"
    voxels = set()
    index = 0
    for p in range(0, len(body), 2):
        value, count = body[p], body[p + 1]
        assert value in (0, 1) and count >= 1, (value, count)
        if value:
            for i in range(index, index + count):
                voxels.add((i // (d * d), i % d, (i // d) % d))  # (x, y, z) from x*D*D + z*D + y
        index += count
    assert index == d * d * d, "runs cover %d cells, not %d" % (index, d * d * d)
    info = {"dim": d, "translate": [float(x) for x in header["translate"]], "scale": float(header["scale"][0])}
    return voxels, info


def read_vox(path):
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"VOX ", data[:4]
    (version,) = struct.unpack_from("<i", data, 4)
    assert data[8:12] == b"MAIN"
    content, children = struct.unpack_from("<ii", data, 12)
    assert content == 0 and 20 + children == len(data), (children, len(data))
    models, palette, transforms, shapes = [], None, {}, {}
    pos = 20

    def string(p):
        (n,) = struct.unpack_from("<i", data, p)
        return data[p + 4:p + 4 + n].decode("ascii"), p + 4 + n

    def dictionary(p):
        (n,) = struct.unpack_from("<i", data, p)
        p += 4
        d = {}
        for _ in range(n):
            k, p = string(p)
            v, p = string(p)
            d[k] = v
        return d, p

    while pos < len(data):
        cid = data[pos:pos + 4].decode("ascii")
        n, m = struct.unpack_from("<ii", data, pos + 4)
        assert m == 0, "chunk %s has children" % cid
        body = pos + 12
        if cid == "SIZE":
            models.append({"size": struct.unpack_from("<iii", data, body), "xyzi": b""})
            assert all(1 <= s <= 256 for s in models[-1]["size"]), models[-1]["size"]
        elif cid == "XYZI":
            (count,) = struct.unpack_from("<i", data, body)
            assert n == 4 + 4 * count
            models[-1]["xyzi"] = data[body + 4:body + 4 + 4 * count]
        elif cid == "nTRN":
            (node,) = struct.unpack_from("<i", data, body)
            _, p = dictionary(body + 4)
            child, reserved, layer, frames = struct.unpack_from("<iiii", data, p)
            assert reserved == -1 and frames == 1
            frame, p = dictionary(p + 16)
            transforms[node] = (child, [int(x) for x in frame.get("_t", "0 0 0").split()])
        elif cid == "nSHP":
            (node,) = struct.unpack_from("<i", data, body)
            _, p = dictionary(body + 4)
            (nmodels,) = struct.unpack_from("<i", data, p)
            assert nmodels == 1
            (model,) = struct.unpack_from("<i", data, p + 4)
            shapes[node] = model
        elif cid == "RGBA":
            palette = [tuple(data[body + 4 * i:body + 4 * i + 3]) for i in range(256)]
        pos = body + n
    assert pos == len(data)
    place = {shapes[child]: t for child, t in transforms.values() if child in shapes}
    voxels = {}
    for m, model in enumerate(models):
        t, size = place[m], model["size"]
        xyzi = model["xyzi"]
        for p in range(0, len(xyzi), 4):
            x, y, z, c = xyzi[p:p + 4]
            assert x < size[0] and y < size[1] and z < size[2] and c >= 1
            cell = (t[0] + x - size[0] // 2, t[1] + y - size[1] // 2, t[2] + z - size[2] // 2)
            assert cell not in voxels, "voxel %s twice" % (cell,)
            voxels[cell] = palette[c - 1] if palette else c
    return voxels, {"version": version, "models": len(models), "colors": len(set(voxels.values()))}


def read_vdb(path):
    import pyopenvdb

    grids = {g.name: g for g in pyopenvdb.readAll(path)[0]}
    density = grids["density"]
    on = set()
    # Active values come as voxels or tiles (boxes of voxels, for uniform blocks).
    for item in density.citerOnValues():
        (x0, y0, z0), (x1, y1, z1) = item["min"], item["max"]
        assert item["value"] == 1.0
        for x in range(x0, x1 + 1):
            for y in range(y0, y1 + 1):
                for z in range(z0, z1 + 1):
                    on.add((x, y, z))
    assert len(on) == density.activeVoxelCount()
    xform = density.transform
    info = {"grids": sorted(grids), "count_voxels": grids["count"].activeVoxelCount() if "count" in grids else -1,
            "corner": list(xform.indexToWorld((-0.5, -0.5, -0.5)))}
    return on, info


def check(path, grid):
    ext = path.rsplit(".", 1)[-1].lower()
    reader = {"binvox": read_binvox, "vox": read_vox, "vdb": read_vdb}[ext]
    voxels, info = reader(path)
    cells = set(voxels)
    status = 0
    if grid is not None:
        occupied = {tuple(c["ijk"]) for c in grid["cells"]}
        missing = occupied - cells
        if missing:
            print("MISMATCH %s: %d occupied cells missing, e.g. %s" % (path, len(missing), sorted(missing)[:3]))
            status = 1
        expected = grid["occupied_cells"] + grid.get("solid_cells", 0)
        if len(cells) != expected:
            print("MISMATCH %s: %d voxels, the grid has %d occupied + %d solid" %
                  (path, len(cells), grid["occupied_cells"], grid.get("solid_cells", 0)))
            status = 1
    with open(path + ".cells", "w") as f:
        for c in sorted(cells):
            f.write("%d %d %d\n" % c)
    print("RESULT %s voxels=%d %s" % (path, len(cells), " ".join("%s=%s" % (k, str(v).replace(" ", ""))
                                                              for k, v in info.items())), flush=True)
    return status


def main():
    args = sys.argv[1:]
    grid = None
    if args and args[0].endswith(".json"):
        with open(args.pop(0)) as f:
            grid = json.load(f)
    status = 0
    for path in args:
        try:
            status |= check(path, grid)
        except Exception as e:  # a malformed file fails its own check; the others still run
            print("MISMATCH %s: %s: %s" % (path, type(e).__name__, e))
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
