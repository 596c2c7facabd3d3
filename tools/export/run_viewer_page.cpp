// vox-export to a viewer page (.html).
#include <cctype>
#include <filesystem>

#include "runs.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/export/viewer_page.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"

namespace vox::export_tool {

bool isViewerPagePath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".html" || ext == ".htm";
}

int runViewerPage(const Options& opt) {
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  if (!viewerPageAvailable()) viewerPageHtml({}, {});  // the build's UsageError, before reading a large grid
  checkOutputPath(opt.output, {opt.grid});
  ViewerPageOptions page;
  page.color = parseColorMode(opt.color);
  page.title = std::filesystem::path(opt.grid).filename().string();
  ProgressBar bar("exporting", opt.common.quiet);
  const GridFile file = readGridOrSet(opt.grid);
  bar.update(0.3);
  ViewerDataStats stats;
  namingGrid(opt, [&] { writeViewerPage(opt.output, file.grid, file.scene, page, &stats); });
  bar.finish();
  if (opt.stats)
    std::fprintf(stderr,
                 "voxels: %llu\nsurface_vertices: %llu\nsurface_triangles: %llu\nlevel_surface_vertices: %llu\n"
                 "level_surface_triangles: %llu\nstored_ids: %llu\ndata_bytes: %llu\noutput_bytes: %llu\n"
                 "total_seconds: %.6f\n",
                 (unsigned long long)stats.voxels, (unsigned long long)stats.surfaceVertices,
                 (unsigned long long)stats.surfaceTriangles, (unsigned long long)stats.levelVertices,
                 (unsigned long long)stats.levelTriangles, (unsigned long long)stats.storedIds,
                 (unsigned long long)stats.dataBytes, (unsigned long long)stats.pageBytes, secondsSince(start));
  return kExitOk;
}

}  // namespace vox::export_tool
