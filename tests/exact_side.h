// CGAL's exact inside test of a closed triangle soup (equal positions welded): the independent judge of signs in
// the distance tests and in bench/openvdb_sdf.cpp.
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <map>
#include <memory>
#include <vector>

#include "vox/core/scene.h"

namespace vox::testing {

class ExactSide {
 public:
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

  explicit ExactSide(const std::vector<Triangle>& triangles) {
    std::map<std::array<double, 3>, size_t> index;
    std::vector<Kernel::Point_3> points;
    std::vector<std::vector<size_t>> faces;
    for (const Triangle& t : triangles) {
      std::vector<size_t> f;
      for (const Vec3& v : t.v) {
        const auto [it, added] = index.emplace(std::array<double, 3>{v.x, v.y, v.z}, points.size());
        if (added) points.emplace_back(v.x, v.y, v.z);
        f.push_back(it->second);
      }
      faces.push_back(f);
    }
    CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, faces, mesh_);
    side_ = std::make_unique<CGAL::Side_of_triangle_mesh<Mesh, Kernel>>(mesh_);
  }
  // -1 inside, 0 on the boundary, 1 outside.
  int side(const Vec3& p) const {
    const auto s = (*side_)(Kernel::Point_3(p.x, p.y, p.z));
    return s == CGAL::ON_BOUNDED_SIDE ? -1 : (s == CGAL::ON_BOUNDARY ? 0 : 1);
  }

 private:
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  Mesh mesh_;
  std::unique_ptr<CGAL::Side_of_triangle_mesh<Mesh, Kernel>> side_;
};

}  // namespace vox::testing
