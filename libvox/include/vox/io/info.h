// Grid statistics and their text and JSON forms, as `vox-info` prints them (DESIGN.md "vox-info").
#pragma once

#include <ostream>
#include <string>

#include "vox/io/grid_file.h"

namespace vox {

struct InfoOptions {
  bool json = false;
  bool cells = false;       // JSON: add "cells": [{"ijk": [...], "prims": [...]}, ...]
  bool primitives = false;  // JSON: add "primitives" in world space, full double precision
};

// The summary of a grid file. Doubles are printed with 17 significant digits so they round-trip exactly.
std::string formatGridInfo(const GridFile& file, const InfoOptions& options);
// The same, written to `out` as it is made.
void writeGridInfo(std::ostream& out, const GridFile& file, const InfoOptions& options);
// The same for the grid set at `setPath`, byte for byte the single grid's report, streamed one layer of bricks at a
// time (forEachGridSetLayer; twice with --cells: the totals come before the cells): peak memory is one layer of
// bricks and the scene, not the grid. Throws as readGridSet.
void writeGridSetInfo(std::ostream& out, const std::string& setPath, const InfoOptions& options);

}  // namespace vox
