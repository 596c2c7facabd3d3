# Imports .vdb files as Blender volume objects (bpy.ops.object.volume_import, as File > Import > OpenVDB does) and
# reports what Blender got: one line per file, "RESULT <file> key=value ...", read by
# tests/cli/export_voxel_formats.sh.
#
# Usage: blender -b --factory-startup --python blender_volume.py -- FILE...
# Reported: objects (volume objects made), grids (names, comma-separated), types (data types), loaded (1 when
# Blender's OpenVDB loaded every grid), scale and translate (density's index-to-object matrix: per-axis voxel
# size and the world position of index 0, the first cell's centre), bbox_min/bbox_max (the object's bounding box in
# world space, which Blender computes from the active voxels). Blender's Python API gives no voxel count; the counts
# are checked with pyopenvdb.
import os
import sys

import bpy


def empty_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for vol in list(bpy.data.volumes):
        bpy.data.volumes.remove(vol)


def fmt(v):
    return ",".join("%.9g" % x for x in v)


def report(path):
    empty_scene()
    folder, name = os.path.split(os.path.abspath(path))
    bpy.ops.object.volume_import(filepath=os.path.abspath(path), directory=folder, files=[{"name": name}])
    objs = [o for o in bpy.context.scene.objects if o.type == "VOLUME"]
    if not objs:
        return "error=no_volume_object"
    vol = objs[0].data
    loaded = vol.grids.load() and all(g.load() for g in vol.grids)
    names = [g.name for g in vol.grids]
    types = [g.data_type for g in vol.grids]
    out = ["objects=%d" % len(objs), "grids=%s" % ",".join(names), "types=%s" % ",".join(types),
           "loaded=%d" % int(loaded)]
    if "density" in names:
        m = vol.grids["density"].matrix_object
        out.append("scale=%s" % fmt([m[0][0], m[1][1], m[2][2]]))
        out.append("translate=%s" % fmt([m[0][3], m[1][3], m[2][3]]))
    bpy.context.view_layer.update()
    obj = objs[0]
    corners = [obj.matrix_world @ __import__("mathutils").Vector(c) for c in obj.bound_box]
    out.append("bbox_min=%s" % fmt([min(c[a] for c in corners) for a in range(3)]))
    out.append("bbox_max=%s" % fmt([max(c[a] for c in corners) for a in range(3)]))
    return " ".join(out)


def main():
    files = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    for path in files:
        try:
            line = report(path)
        except Exception as e:  # one file's failure is reported, the others still run
            line = "error=%s" % str(e).replace(" ", "_")[:200]
        print("RESULT %s %s" % (path, line), flush=True)


main()
