// Scene importers. Each reads one file and returns a Scene in world space (DESIGN.md "Scene model").
// All throw InputError with the file name and the place (line, node, accessor) on malformed input.
#pragma once

#include <functional>
#include <string>

#include "vox/core/scene.h"

namespace vox {

// Dispatches on the extension: .txt (course format), .obj, .gltf/.glb, .ply. `progress` (may be empty) is called
// with the fraction read while the OBJ and PLY importers parse, from worker threads and from the calling thread, the
// latter every few milliseconds of parsing; return false to cancel (throws vox::Error "PATH: reading cancelled").
// glTF asks it after tinygltf's parse (one call) and every 4096th vertex, index and triangle; the course format
// every 4096th line and object.
Scene loadScene(const std::string& path, const std::function<bool(double)>& progress = {});

// The MIT 6.837 text scene format (grammar in seed-scenes/6837/README.md). TriangleMesh paths are resolved relative
// to the scene file's folder. Procedural materials (Checkerboard, Noise, Marble, Wood) become their first
// material's colour, with a warning. Cameras get CameraSpan::LongerSide: the angle or size spans the image's longer
// side, as in the course's code. `progress` as loadScene's.
Scene importCourseScene(const std::string& path, const std::function<bool(double)>& progress = {});
// Wavefront OBJ, read by libvox's own reader in double precision (a coordinate comes back bit for bit from 17
// significant digits): polygons of any size fan-triangulated, negative indices, line continuations. .mtl: Kd ->
// diffuse, Ks -> specular, Ns -> exponent, Ni -> indexOfRefraction; faces without a material get a default white
// one (the last material). `mtllib` files are resolved in the OBJ file's folder: a missing one is a warning, one
// outside that folder or not a regular file an InputError. Throws InputError "file:line: ..." on a malformed
// number (NaN, infinity, out of range), an index outside the vertices, or a file over 4 GiB. `progress` as
// loadScene's.
Scene importObj(const std::string& path, const std::function<bool(double)>& progress = {});
// glTF 2.0 (.gltf, .glb) through tinygltf: node hierarchy (matrix or TRS), triangle primitives (indexed or not),
// baseColorFactor, cameras, KHR_lights_punctual. Other primitive modes are skipped with a warning.
// Scene: the default scene, else scene 0, else every root node. Triangle strips and fans are converted.
// Camera: the first camera node in depth-first order; yfov (radians) -> fovDegrees, orthographic ymag ->
// orthoHeight = 2 * ymag; looks down the node's -Z with +Y up. Materials: baseColorFactor RGB -> diffuse; base
// colour textures are not sampled (one warning). Lights: directional along the node's -Z, point at the node's
// origin, spot -> point (warning). glTF intensities are physical (lux, candela) and a Phong shader has no exposure
// to map them, so Light::color = color * min(intensity, 1) and point lights get no distance falloff (attenuation
// 1 0 0). Accessor, bufferView and index ranges are checked: InputError "file: accessor N: ...". `progress` as
// loadScene's.
Scene importGltf(const std::string& path, const std::function<bool(double)>& progress = {});
// PLY triangle meshes (ASCII and binary), read by libvox itself: coordinates exact (double properties bit for bit),
// faces fan-triangulated. Throws InputError naming the file and the line (ASCII) or element and byte (binary) on a
// value that does not fit its declared type, a vertex index out of range, or an element count the file cannot hold.
// `progress` as loadScene's.
Scene importPly(const std::string& path, const std::function<bool(double)>& progress = {});

}  // namespace vox
