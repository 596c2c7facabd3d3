// Grid statistics and their text and JSON forms, as `vox-info` prints them (DESIGN.md "vox-info").
#pragma once

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

}  // namespace vox
