"""Grid.save and libvox.load: every format, byte for byte what vox-voxelize and vox-export write, and read back by
independent readers (a small reader of the published binvox and MagicaVoxel layouts here, pyopenvdb for .vdb)."""

import struct
import warnings

import numpy as np
import pytest

import libvox
from conftest import SCENES, assert_same_grid, cli_voxelize, run_tool

MESH_FORMATS = [".ply", ".obj", ".off", ".stl", ".glb", ".gltf"]


@pytest.fixture(scope="module")
def grid():
    # Filled, so that solid cells take part; not cubic cells (binvox warns); a scene with materials.
    return libvox.voxelize(SCENES / "scene5_05_sphere_triangles.txt", resolution=24, fill=True)


def voxel_set(g):
    return {tuple(c) for c in g.indices} | {tuple(c) for c in g.solid_indices}


def test_vgrid_round_trip(tools, tmp_path, grid):
    path = tmp_path / "g.vgrid"
    grid.save(path)
    back = libvox.load(path)
    assert_same_grid(back, grid)
    assert back.source == str(path)
    # vox-voxelize writes the same file.
    cli = cli_voxelize(tools, tmp_path, SCENES / "scene5_05_sphere_triangles.txt", "--res", 24, "--fill")
    assert path.read_bytes() == cli.read_bytes()


@pytest.mark.parametrize("ext", MESH_FORMATS)
@pytest.mark.parametrize("faces,color", [("exposed", "count"), ("merged", "material"), ("all", "none")])
def test_mesh_formats_as_vox_export(tools, tmp_path, grid, ext, faces, color):
    vgrid = tmp_path / "g.vgrid"
    grid.save(vgrid)
    ours, cli = tmp_path / f"py{ext}", tmp_path / f"cli{ext}"
    grid.save(ours, faces=faces, color=color)
    run_tool(tools, "vox-export", vgrid, "-o", cli, "--faces", faces, "--color", color)
    assert ours.stat().st_size > 0
    if ext == ".obj" and color != "none":
        # The OBJ names its .mtl; the two files are named apart, so compare all but that line.
        assert ours.read_text().replace("py.mtl", "X") == cli.read_text().replace("cli.mtl", "X")
        assert ours.with_suffix(".mtl").read_bytes() == cli.with_suffix(".mtl").read_bytes()
    else:
        assert ours.read_bytes() == cli.read_bytes()


def test_mesh_arrays(grid):
    v, f, c = grid.mesh(faces="exposed", color="count")
    assert v.dtype == np.float64 and f.dtype == np.int32 and c.dtype == np.uint8
    assert f.shape[1] == 3 and c.shape == (len(f), 4) and np.all(c[:, 3] == 255)
    assert f.min() >= 0 and f.max() < len(v)
    # Closed and 2-manifold: every edge has exactly two faces, once in each direction.
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    assert len({tuple(e) for e in edges}) == len(edges)
    assert {tuple(e) for e in edges} == {(b, a) for a, b in edges}
    # The enclosed volume (divergence theorem) is the voxels' volume.
    a, b, cc = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    volume = np.einsum("ij,ij->i", a, np.cross(b, cc)).sum() / 6
    assert volume == pytest.approx(len(voxel_set(grid)) * np.prod(grid.pitch), rel=1e-9)
    v2, f2, c2 = grid.mesh()
    assert c2 is None and len(f2) < len(f)


def read_binvox(path):
    """The published binvox layout: ASCII header, then (value, count) byte pairs over x*D*D + z*D + y."""
    data = path.read_bytes()
    header, _, body = data.partition(b"data\n")
    lines = header.decode().split("\n")
    assert lines[0] == "#binvox 1"
    fields = {l.split()[0]: l.split()[1:] for l in lines[1:] if l}
    d = int(fields["dim"][0])
    pairs = np.frombuffer(body, dtype=np.uint8).reshape(-1, 2)
    flat = np.repeat(pairs[:, 0], pairs[:, 1]).astype(bool)
    assert flat.size == d ** 3
    xzy = flat.reshape(d, d, d)  # [x, z, y]
    return xzy.transpose(0, 2, 1), [float(t) for t in fields["translate"]], float(fields["scale"][0])


def test_binvox(tools, tmp_path, grid):
    path = tmp_path / "g.binvox"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # cubic cells: no warning
        grid.save(path)
    cube, translate, scale = read_binvox(path)
    nx, ny, nz = grid.dims
    assert cube.shape[0] == max(grid.dims)
    assert np.array_equal(cube[:nx, :ny, :nz], grid.dense())
    assert not cube[nx:].any() and not cube[:, ny:].any() and not cube[:, :, nz:].any()
    assert np.allclose(translate, grid.bounds[0])
    vgrid = tmp_path / "g.vgrid"
    grid.save(vgrid)
    run_tool(tools, "vox-export", vgrid, "-o", tmp_path / "cli.binvox")
    assert path.read_bytes() == (tmp_path / "cli.binvox").read_bytes()
    stretched = libvox.voxelize(SCENES / "scene5_05_sphere_triangles.txt", dims=(10, 7, 3))
    with pytest.warns(UserWarning, match="binvox voxels are cubes"):
        stretched.save(tmp_path / "s.binvox")


def read_vox(path):
    """The published MagicaVoxel layout: 'VOX ' version, MAIN, then SIZE / XYZI pairs and RGBA (palette)."""
    data = path.read_bytes()
    assert data[:4] == b"VOX "
    pos, models, palette = 20, [], None  # after the MAIN chunk's header
    while pos < len(data):
        cid, content, children = struct.unpack_from("<4sii", data, pos)
        body = data[pos + 12:pos + 12 + content]
        if cid == b"XYZI":
            n = struct.unpack_from("<i", body)[0]
            models.append(np.frombuffer(body[4:4 + 4 * n], dtype=np.uint8).reshape(n, 4))
        elif cid == b"RGBA":
            palette = np.frombuffer(body, dtype=np.uint8).reshape(256, 4)
        pos += 12 + content + children
    return models, palette


def test_magicavoxel(tools, tmp_path, grid):
    path = tmp_path / "g.vox"
    grid.save(path, color="count")
    models, palette = read_vox(path)
    assert len(models) == 1  # the grid fits one 256^3 model
    xyzi = models[0]
    assert {tuple(int(x) for x in v[:3]) for v in xyzi} == voxel_set(grid)
    # Colour index i is palette entry i - 1; occupied cells get their count colour, solid cells grey.
    colour = {tuple(int(x) for x in v[:3]): tuple(palette[v[3] - 1][:3]) for v in xyzi}
    counts = grid.colors("count")
    assert all(colour[tuple(c)] == tuple(counts[n][:3]) for n, c in enumerate(grid.indices))
    assert all(colour[tuple(c)] == (153, 153, 153) for c in grid.solid_indices if tuple(c) not in
               {tuple(i) for i in grid.indices})
    vgrid = tmp_path / "g.vgrid"
    grid.save(vgrid)
    run_tool(tools, "vox-export", vgrid, "-o", tmp_path / "cli.vox", "--color", "count")
    assert path.read_bytes() == (tmp_path / "cli.vox").read_bytes()


def test_vdb(tmp_path, grid):
    pyopenvdb = pytest.importorskip("pyopenvdb")
    path = tmp_path / "g.vdb"
    grid.save(path)
    density = pyopenvdb.read(str(path), "density")
    active = set()
    for item in density.citerOnValues():
        lo, hi = item.min, item.max
        for i in range(lo[0], hi[0] + 1):
            for j in range(lo[1], hi[1] + 1):
                for k in range(lo[2], hi[2] + 1):
                    active.add((i, j, k))
    assert active == voxel_set(grid)
    centre = density.transform.indexToWorld((0, 0, 0))
    assert np.allclose(centre, grid.bounds[0] + grid.pitch / 2)


def test_save_refuses(tmp_path, grid):
    with pytest.raises(libvox.UsageError, match="extension|format"):
        grid.save(tmp_path / "g.xyz")
    with pytest.raises(OSError):
        grid.save(tmp_path / "missing" / "g.ply")
    with pytest.raises(libvox.UsageError):
        grid.save(tmp_path / "g.ply", faces="some")
    vgrid = tmp_path / "g.vgrid"
    grid.save(vgrid)
    loaded = libvox.load(vgrid)
    with pytest.raises(libvox.UsageError):
        loaded.save(vgrid)  # its own file


def test_load_grid_set(tools, tmp_path):
    """A grid set (vox-voxelize --bricks) loads as the single grid it stands for."""
    scene = SCENES / "scene5_07_bunny_mesh_1k.txt"
    manifest = tmp_path / "set.vgrid"
    run_tool(tools, "vox-voxelize", scene, "-o", manifest, "--res", 40, "--fill", "--bricks", 3, 2, 2)
    loaded = libvox.load(manifest)
    assert_same_grid(loaded, libvox.voxelize(scene, resolution=40, fill=True))
    assert loaded.solid_count > 0


def test_save_grid_set(tools, tmp_path):
    """Grid.save(..., bricks=...) writes the grid set vox-voxelize --bricks writes: the same cells once loaded, the
    same vox-info report."""
    scene = SCENES / "scene5_07_bunny_mesh_1k.txt"
    for fill, bounds in [(False, None), (True, None), (False, ((-0.05, 0.0, -0.1), (0.2, 0.3, 0.05)))]:
        grid = libvox.voxelize(scene, resolution=40, fill=fill, bounds=bounds)
        ours = tmp_path / f"py_{fill}_{bounds is None}.vgrid"
        grid.save(ours, bricks=(3, 2, 2))
        assert_same_grid(libvox.load(ours), grid)
        cli = tmp_path / f"cli_{fill}_{bounds is None}.vgrid"
        args = ["--res", 40, "--bricks", 3, 2, 2] + (["--fill"] if fill else [])
        if bounds:
            args += ["--bounds", *bounds[0], *bounds[1]]
        run_tool(tools, "vox-voxelize", scene, "-o", cli, *args)
        assert run_tool(tools, "vox-info", ours, "--json", "--cells") == run_tool(tools, "vox-info", cli, "--json",
                                                                                 "--cells")
    with pytest.raises(libvox.UsageError, match="bricks"):
        grid.save(tmp_path / "x.ply", bricks=2)
    with pytest.raises(libvox.UsageError):
        grid.save(tmp_path / "x.vgrid", bricks=(1000, 1, 1))


def test_viewer_page_as_vox_export(tools, tmp_path, grid):
    vgrid = tmp_path / "g.vgrid"
    grid.save(vgrid)
    loaded = libvox.load(vgrid)  # named after its file, as vox-export titles the page
    try:
        loaded.save(tmp_path / "py.html")
    except libvox.UsageError as e:
        pytest.skip(f"this build has no viewer page: {e}")
    run_tool(tools, "vox-export", vgrid, "-o", tmp_path / "cli.html")
    assert (tmp_path / "py.html").read_bytes() == (tmp_path / "cli.html").read_bytes()
