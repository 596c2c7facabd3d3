// The volume a closed, oriented triangle mesh encloses within one cell, by the divergence theorem one dimension at a
// time (fractions.cpp explains the method and its error). Every inside/outside decision is made in one perturbed
// world: the cell's planes x = X, y = Y, z = Z stand for X + dx, Y + dy, Z + dz with dx >> dy >> dz > 0
// infinitesimal (simulation of simplicity, Edelsbrunner and Muecke 1990), so no surface point lies on a cell's
// plane, the cell is (x0, x1] x (y0, y1] x (z0, z1] for the mesh's points, and the volume, continuous in the
// perturbation, is the unperturbed one.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "vox/core/scene.h"

namespace vox::volume {

struct Polygon {
  std::array<Vec3, 9> v;  // a triangle clipped by six planes has at most 9 corners
  int n = 0;
};

// Sutherland and Hodgman (1974): keeps the part with coordinate `axis` <= value (keepBelow) or >= value. Points
// made on the plane get the plane's coordinate exactly. At most one corner more than `in`.
Polygon clipPolygon(const Polygon& in, int axis, double value, bool keepBelow);

// The flux of (x, 0, 0) through the polygon (coordinates relative to the cell's low corner): the yz-projected signed
// area of each fan triangle times the mean x of its corners.
double polygonFlux(const Polygon& poly);

// A cell's boundaries (cellBoundary), world space.
struct CellPlanes {
  double lo[3];
  double hi[3];
};

// Where the mesh crosses the vertical line x = X + dx, y = Y + dy: z relative to zOrigin and the change of the
// winding number when the line passes it going up (+1 entering an outward surface, -1 leaving it).
struct LineCrossing {
  double z = 0;
  int jump = 0;
};

// The crossing of triangle t with that line, if any. Decided exactly; z computed from the triangle's section at
// x = X the same way cellMeshVolume computes it, so that the two agree to rounding even where the section runs
// almost along the line.
std::optional<LineCrossing> lineCrossing(const Triangle& t, double X, double Y, double zOrigin);

// The winding-number integral of the mesh over the cell: the sum over `triangles` (the cell's, in any order) of the
// flux of (x - x0, 0, 0) through their parts inside the cell, plus (x1 - x0) times the integral over the high-x face,
// which is the same sum one dimension down plus (y1 - y0) times `edgeIntegral`: the integral of the winding number
// along the face's high-y edge (x1 + dx, y1 + dy, z in (z0, z1]), which the caller gets from lineCrossing over the
// whole line. World units cubed; positive for an outward-oriented mesh.
double cellMeshVolume(std::span<const Triangle* const> triangles, const CellPlanes& cell, double edgeIntegral);

}  // namespace vox::volume
