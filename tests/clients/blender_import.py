# Imports exported voxel meshes with Blender's own importers, as a user would, and reports what Blender got: one
# line per file, "RESULT <file> key=value ...", read by tests/cli/export_clients.sh.
#
# Usage: blender -b --factory-startup --python blender_import.py -- FILE...
# Importers: .ply io_mesh_ply (reads per-vertex colours only), .obj wm.obj_import (the C++ importer of Blender 3.4,
# reads .mtl materials), .glb/.gltf import_scene.gltf, .stl import_mesh.stl. One Blender run takes many files
# (Blender starts in about 2 s): the scene is emptied between files.
#
# Reported per file (all imported mesh objects taken together):
#   verts, faces: Blender's counts after import;
#   boundary: edges with one face; nonmanifold: edges with more than two faces (bmesh);
#   pieces: connected components of faces through shared edges;
#   colors: distinct colours Blender shows: colour attribute values (per corner) plus material base colours;
#   color_attrs, materials: how many colour attributes and materials the mesh has;
#   exact: faces whose colour attribute is the same at all corners (1.0 when there is none).
import sys

import bmesh
import bpy

# Debian 12's Blender 3.4 glTF add-on uses numpy.bool, removed in numpy 1.24 (Debian 12 ships 1.24.2): without
# this every glTF import fails (Khronos' own Duck.glb too). Its bug, not ours.
import warnings

import numpy

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # numpy 1.24 warns on the look-up itself
    if not hasattr(numpy, "bool"):
        numpy.bool = bool


def empty_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)
    for mat in list(bpy.data.materials):
        bpy.data.materials.remove(mat)


def import_file(path):
    ext = path.rsplit(".", 1)[-1].lower()
    if ext == "ply":
        return bpy.ops.import_mesh.ply(filepath=path)
    if ext == "obj":
        return bpy.ops.wm.obj_import(filepath=path)
    if ext in ("glb", "gltf"):
        return bpy.ops.import_scene.gltf(filepath=path)
    if ext == "stl":
        return bpy.ops.import_mesh.stl(filepath=path)
    raise ValueError("no Blender importer for ." + ext)


def material_color(mat):
    if mat.use_nodes and mat.node_tree:
        for node in mat.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                c = node.inputs["Base Color"].default_value
                return (round(c[0], 4), round(c[1], 4), round(c[2], 4))
    c = mat.diffuse_color
    return (round(c[0], 4), round(c[1], 4), round(c[2], 4))


def measure(objects):
    verts = faces = boundary = nonmanifold = pieces = color_attrs = 0
    exact_faces = 0
    colors = set()
    materials = set()
    for obj in objects:
        mesh = obj.data
        for slot_mat in mesh.materials:
            if slot_mat is not None:
                materials.add(slot_mat.name)
                colors.add(("m",) + material_color(slot_mat))
        attrs = list(mesh.color_attributes)
        color_attrs += len(attrs)
        corner_colors = None
        if attrs:
            attr = attrs[0]
            values = [tuple(round(x, 4) for x in d.color[:3]) for d in attr.data]
            colors.update(values)
            corner_colors = (attr.domain, values)
        bm = bmesh.new()
        bm.from_mesh(mesh)
        verts += len(bm.verts)
        faces += len(bm.faces)
        for e in bm.edges:
            n = len(e.link_faces)
            boundary += n == 1
            nonmanifold += n > 2
        # Pieces: union-find over faces through edges.
        bm.faces.ensure_lookup_table()
        parent = list(range(len(bm.faces)))

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for e in bm.edges:
            lf = e.link_faces
            for k in range(1, len(lf)):
                a, b = find(lf[0].index), find(lf[k].index)
                if a != b:
                    parent[a] = b
        pieces += sum(1 for i in range(len(parent)) if find(i) == i)
        if corner_colors is None:
            exact_faces += len(bm.faces)
        else:
            domain, values = corner_colors
            for f in mesh.polygons:
                if domain == "CORNER":
                    cs = {values[li] for li in f.loop_indices}
                elif domain == "POINT":
                    cs = {values[v] for v in f.vertices}
                else:
                    cs = {0}
                exact_faces += len(cs) == 1
        bm.free()
    exact = exact_faces / faces if faces else 1.0
    return dict(verts=verts, faces=faces, boundary=boundary, nonmanifold=nonmanifold, pieces=pieces,
                colors=len(colors), color_attrs=color_attrs, materials=len(materials), exact="%.4f" % exact)


def main():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    for path in args:
        empty_scene()
        try:
            result = import_file(path)
            if "FINISHED" not in result:
                print("RESULT %s error=%s" % (path, "-".join(sorted(result))), flush=True)
                continue
        except Exception as e:  # report and go on with the next file
            print("RESULT %s error=%s" % (path, str(e).replace(" ", "_").replace("\n", "_")[:200]), flush=True)
            continue
        objects = [o for o in bpy.data.objects if o.type == "MESH"]
        m = measure(objects)
        m["objects"] = len(objects)
        print("RESULT %s %s" % (path, " ".join("%s=%s" % kv for kv in m.items())), flush=True)


main()
