// vox-trace: grid file -> image, by marching rays through the grid.
#include <tbb/info.h>

#include <algorithm>
#include <cstdio>

#include "options.h"
#include "vox/core/tool.h"
#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/io/grid_set.h"
#include "vox/io/image_io.h"
#include "vox/trace/accel.h"
#include "vox/trace/render.h"

namespace {

using namespace vox;
using trace_tool::Options;

// --stats: the walk's counters per ray and the mode's own ranges, as "name: value" lines.
void printStats(const Options& opt, const RenderOptions& ro, const RenderStats& stats) {
  const TraceStats& t = stats.trace;
  const double rays = double(std::max<uint64_t>(t.rays, 1));
  std::fprintf(stderr,
               "rays: %llu\nprimary_rays: %llu\ntrace_seconds: %.6f\nrays_per_second: %.0f\ncells_per_ray: %.3f\n"
               "tests_per_ray: %.3f\nmailbox_skips_per_ray: %.3f\naccel: %s\nthreads: %d\n",
               (unsigned long long)t.rays, (unsigned long long)(uint64_t(ro.width) * ro.height * ro.samples),
               stats.traceSeconds, stats.traceSeconds > 0 ? double(t.rays) / stats.traceSeconds : 0.0,
               double(t.cells) / rays, double(t.tests) / rays, double(t.mailboxSkips) / rays, opt.accel.c_str(),
               opt.common.threads ? int(opt.common.threads) : tbb::info::default_concurrency());
  if (ro.mode == RenderMode::Count) std::fprintf(stderr, "count_scale_max: %.3f\n", stats.countMax);
  if (ro.mode == RenderMode::Depth)
    std::fprintf(stderr, "depth_min: %.9g\ndepth_max: %.9g\n", stats.depthMin, stats.depthMax);
}

int run(const Options& opt) {
  auto threads = cli::limitThreads(opt.common.threads);
  // Everything the command line alone decides is checked before the grid is read.
  RenderOptions ro = trace_tool::renderOptions(opt);
  const AccelKind accelKind = parseAccel(opt.accel);

  const GridFile file = readGridOrSet(opt.grid);
  ro.camera = trace_tool::resolveCamera(opt, file);
  const Accel accel = buildAccel(file.scene, file.grid, accelKind);

  ProgressBar bar("tracing", opt.common.quiet);
  ro.progress = [&](double f) { bar.update(f); };
  RenderStats stats;
  Image image = traceImage(file.scene, accel, ro, &stats);
  bar.finish();
  if (ro.mode == RenderMode::Depth && !imageFormatHoldsFloat(opt.output)) image = depthToGrey(image);
  writeImage(opt.output, image);
  if (opt.stats) printStats(opt, ro, stats);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (auto code = trace_tool::parseCommandLine(argc, argv, opt)) return *code;
  return runTool("vox-trace", [&] { return run(opt); });
}
