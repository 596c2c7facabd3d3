// vox-voxelize-mpi: vox-voxelize over Open MPI ranks. A grid set's bricks, or a batch of scenes, are handed out one
// at a time (work_queue.h); every rank reads the scene itself and writes its own files; rank 0 gathers what each
// rank did, prints the one error of a failed run (or each failed scene of a batch) and writes the manifest last.
#include <mpi.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>

#include "../common/cli.h"
#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/import/import.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"
#include "vox/sets/fill_set.h"
#include "vox/sets/voxelize_set.h"
#include "vox/voxelize/bricks.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"
#include "broadcast.h"
#include "work_queue.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string scene;
  std::string batch;
  std::string output;
  std::vector<uint32_t> grid;
  uint32_t resolution = 0;
  std::vector<double> bounds;
  std::string method = "exact";
  bool fill = false;
  bool stats = false;
  std::vector<uint32_t> bricks;
  vox::cli::CommonOptions common;
};

// What one rank reports to rank 0 at the end: its first failure (code 0: none), its counters, and the items it
// finished (bricks of a set, or scenes of a batch with their own outcome).
struct Outcome {
  int32_t code = 0;
  std::string message;
  double seconds = 0, peakMb = 0;
  uint64_t items = 0;
  std::vector<vox::BrickEntry> bricks;
  std::vector<std::pair<uint64_t, std::pair<int32_t, std::string>>> scenes;  // index, (code, message)
};

// Packing for MPI_Gatherv: plain bytes; both ends are this program, so no versioning.
struct Packer {
  std::string bytes;
  template <typename T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put(const std::string& s) {
    put(uint64_t(s.size()));
    bytes += s;
  }
};
struct Unpacker {
  const std::string& bytes;
  size_t pos = 0;
  template <typename T>
  void get(T& v) {
    VOX_CHECK(pos + sizeof(T) <= bytes.size());
    std::memcpy(&v, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
  }
  void get(std::string& s) {
    uint64_t n = 0;
    get(n);
    VOX_CHECK(n <= bytes.size() - pos);
    s = bytes.substr(pos, n);
    pos += n;
  }
};

std::string pack(const Outcome& o) {
  Packer p;
  p.put(o.code);
  p.put(o.message);
  p.put(o.seconds);
  p.put(o.peakMb);
  p.put(o.items);
  p.put(uint64_t(o.bricks.size()));
  for (const auto& e : o.bricks) {
    for (uint32_t i : e.index) p.put(i);
    p.put(e.file);
    p.put(e.fileSize);
    p.put(e.fileChecksum);
    p.put(e.occupied);
    p.put(e.references);
    p.put(e.solid);
  }
  p.put(uint64_t(o.scenes.size()));
  for (const auto& [index, result] : o.scenes) {
    p.put(index);
    p.put(result.first);
    p.put(result.second);
  }
  return p.bytes;
}

Outcome unpack(const std::string& bytes) {
  Outcome o;
  Unpacker u{bytes};
  u.get(o.code);
  u.get(o.message);
  u.get(o.seconds);
  u.get(o.peakMb);
  u.get(o.items);
  uint64_t n = 0;
  u.get(n);
  o.bricks.resize(n);
  for (auto& e : o.bricks) {
    for (uint32_t& i : e.index) u.get(i);
    u.get(e.file);
    u.get(e.fileSize);
    u.get(e.fileChecksum);
    u.get(e.occupied);
    u.get(e.references);
    u.get(e.solid);
  }
  u.get(n);
  o.scenes.resize(n);
  for (auto& [index, result] : o.scenes) {
    u.get(index);
    u.get(result.first);
    u.get(result.second);
  }
  return o;
}

// Every rank's outcome on rank 0 (empty elsewhere).
std::vector<Outcome> gatherOutcomes(const Outcome& mine, int rank, int size) {
  const std::string bytes = pack(mine);
  const int length = int(bytes.size());
  std::vector<int> lengths(static_cast<size_t>(size)), offsets(static_cast<size_t>(size));
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (rank == 0) {
    size_t total = 0;
    for (int r = 0; r < size; ++r) {
      offsets[size_t(r)] = int(total);
      total += size_t(lengths[size_t(r)]);
    }
    all.resize(total);
  }
  MPI_Gatherv(bytes.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
  std::vector<Outcome> out;
  if (rank == 0)
    for (int r = 0; r < size; ++r)
      out.push_back(unpack(all.substr(size_t(offsets[size_t(r)]), size_t(lengths[size_t(r)]))));
  return out;
}

// Runs body, turning an exception into the exit code and message vox::runTool would print.
int32_t capture(const std::function<void()>& body, std::string& message) {
  try {
    body();
    return vox::kExitOk;
  } catch (...) {
    return vox::currentExceptionExit(message);
  }
}

// Every error line of every rank: the tools' one format (vox::errorLine: escaped, one line).
void printError(const std::string& message) { std::fputs(vox::errorLine("vox-voxelize-mpi", message).c_str(), stderr); }

double peakMemoryMb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

vox::VoxelizeOptions voxelizeOptions(const Options& opt) {
  vox::VoxelizeOptions vo;
  vo.method = vox::parseMethod(opt.method);
  if (!opt.grid.empty()) vo.dims = std::array<uint32_t, 3>{opt.grid[0], opt.grid[1], opt.grid[2]};
  if (opt.resolution) vo.resolution = opt.resolution;
  if (!opt.bounds.empty())
    vo.bounds = vox::Box{{opt.bounds[0], opt.bounds[1], opt.bounds[2]}, {opt.bounds[3], opt.bounds[4], opt.bounds[5]}};
  vo.memoryLimitBytes = vox::memoryBudgetBytes();
  return vo;
}

// Like vox-voxelize: what the scene asks for is named with the scene.
template <typename F>
auto namingScene(const std::string& scene, F&& f) {
  try {
    return f();
  } catch (const vox::LimitError& e) {
    vox::fail<vox::LimitError>(scene, ": ", e.what());
  } catch (const vox::InputError& e) {
    vox::fail<vox::InputError>(scene, ": ", e.what());
  }
}

void printRankStats(const std::vector<Outcome>& all, double total) {
  for (size_t r = 0; r < all.size(); ++r)
    std::fprintf(stderr, "rank_%zu: items %llu work_seconds %.3f peak_memory_mb %.1f\n", r,
                 (unsigned long long)all[r].items, all[r].seconds, all[r].peakMb);
  double peak = 0;
  for (const auto& o : all) peak = std::max(peak, o.peakMb);
  std::fprintf(stderr, "ranks: %zu\ntotal_seconds: %.6f\nmax_peak_memory_mb: %.1f\n", all.size(), total, peak);
}

// --bricks: every rank plans the same grid from the same scene; bricks with the most candidates go first.
int runSet(const Options& opt, int rank, int size) {
  using namespace vox;
  const auto start = Clock::now();
  const std::array<uint32_t, 3> bricks{opt.bricks[0], opt.bricks[1], opt.bricks[2]};
  Outcome mine;
  Scene scene;
  Grid plan;
  GridSetManifest set;
  std::vector<std::vector<uint32_t>> candidates;
  std::vector<uint64_t> order;
  const VoxelizeOptions vo = voxelizeOptions(opt);
  std::unique_ptr<GridSetOutput> output;  // rank 0 makes the set's generation folder; the others register it
  mine.code = capture(
      [&] {
        checkOutputPath(opt.output, {opt.scene});
        checkGridSetOutput(opt.output);
        scene = loadScene(opt.scene);
        namingScene(opt.scene, [&] {
          plan = planGrid(scene, vo);
          checkBrickCounts(plan.dims, bricks);
          if (vo.bounds) plan.outsidePrims = primitivesOutside(scene, plan);
          candidates = brickCandidates(scene, plan, bricks, vo.memoryLimitBytes);
        });
        if (rank == 0) output = std::make_unique<GridSetOutput>(opt.output);
      },
      mine.message);
  const std::string folder = mpi::broadcastString(MPI_COMM_WORLD, output ? output->folder() : std::string());
  if (mine.code == kExitOk)
    mine.code = capture(
        [&] {
          if (folder.empty()) fail<Error>("rank 0 could not start the set");
          if (rank != 0) output = std::make_unique<GridSetOutput>(opt.output, folder);
          // Every rank encodes the scene file to know its checksum (the bricks name it); rank 0 writes it.
          set = {plan.bounds,
                 plan.dims,
                 plan.method,
                 bricks,
                 writeGridSetScene(opt.output, folder, scene, plan, rank == 0),
                 {}};
          for (uint64_t b = 0; b < candidates.size(); ++b)
            if (!candidates[b].empty()) order.push_back(b);
          std::stable_sort(order.begin(), order.end(),
                           [&](uint64_t a, uint64_t b) { return candidates[a].size() > candidates[b].size(); });
        },
        mine.message);
  int anyFailed = mine.code;
  // Also the barrier that makes the brick folder exist before any rank writes into it.
  MPI_Allreduce(MPI_IN_PLACE, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (!anyFailed) {
    ProgressBar bar("voxelizing bricks", opt.common.quiet || rank != 0);
    std::atomic<uint64_t> done{0};
    mpi::runWorkQueue(MPI_COMM_WORLD, order.size(), [&](uint64_t item) {
      const auto t = Clock::now();
      mine.code = capture(
          [&] {
            namingScene(opt.scene, [&] {
              const uint64_t b = order[item];
              mine.bricks.push_back(writeBrick(opt.output, set, scene, plan, brickIndex(bricks, b), candidates[b], vo));
            });
          },
          mine.message);
      mine.seconds += std::chrono::duration<double>(Clock::now() - t).count();
      ++mine.items;
      bar.update(double(++done) / double(order.size()));  // rank 0's own share: a rough bar
      return mine.code == kExitOk;
    });
    bar.finish();
  }
  std::vector<uint64_t>().swap(order);
  std::vector<std::vector<uint32_t>>().swap(candidates);
  mine.peakMb = peakMemoryMb();
  const std::vector<Outcome> all = gatherOutcomes(mine, rank, size);
  int code = kExitOk;
  if (rank == 0) {
    for (size_t r = 0; r < all.size() && code == kExitOk; ++r)
      if (all[r].code != kExitOk) {
        code = all[r].code;
        printError((size > 1 ? "rank " + std::to_string(r) + ": " : std::string()) + all[r].message);
      }
    if (code == kExitOk) {
      std::string message;
      code = capture(
          [&] {
            GridSetManifest m = set;
            for (const auto& o : all) m.entries.insert(m.entries.end(), o.bricks.begin(), o.bricks.end());
            std::erase_if(m.entries, [](const BrickEntry& e) { return e.occupied == 0; });
            std::sort(m.entries.begin(), m.entries.end(), [&](const BrickEntry& a, const BrickEntry& b) {
              return brickNumber(bricks, a.index) < brickNumber(bricks, b.index);
            });
            // The fill needs every brick's cells: rank 0 runs it over the written bricks (fillGridSet).
            if (opt.fill)
              namingScene(opt.scene, [&] {
                const FillReport report =
                    fillGridSet(opt.output, m, scene, FillOptions{vo.memoryLimitBytes, {}, {}, false});
                if (!opt.common.quiet)
                  std::fprintf(stderr, "vox-voxelize-mpi: fill: %s\n", describeFill(report).c_str());
              });
            output->commit(m);  // the manifest, then the replaced set's files removed
          },
          message);
      if (code != kExitOk) printError(message);
    }
    if (opt.stats) printRankStats(all, std::chrono::duration<double>(Clock::now() - start).count());
  }
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return code;
}

// The scenes of a batch list: one path a line (relative to the current folder), blank lines and # comments skipped.
std::vector<std::string> readBatchList(const std::string& path) {
  const std::string text = vox::readInputFile(path, "batch list");
  std::vector<std::string> scenes;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    scenes.push_back(line);
  }
  if (scenes.empty()) vox::fail<vox::InputError>(path, ": no scene listed");
  return scenes;
}

// DIR/NAME.vgrid for each scene; two scenes of one name would overwrite each other.
std::vector<std::string> batchOutputs(const std::string& list, const std::vector<std::string>& scenes,
                                      const std::string& dir) {
  std::vector<std::string> outputs;
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < scenes.size(); ++i) {
    const std::string name = std::filesystem::path(scenes[i]).stem().string();
    if (name.empty()) vox::fail<vox::InputError>(list, ": line for '", vox::quoteInput(scenes[i]), "' names no file");
    if (!seen.emplace(name, i).second)
      vox::fail<vox::UsageError>(list, ": two scenes would both write ", name, ".vgrid (",
                                 vox::quoteInput(scenes[seen[name]]), " and ", vox::quoteInput(scenes[i]), ")");
    outputs.push_back((std::filesystem::path(dir) / (name + ".vgrid")).string());
  }
  return outputs;
}

// One scene of a batch, exactly as vox-voxelize would make its grid.
void voxelizeOne(const Options& opt, const std::string& scenePath, const std::string& output) {
  using namespace vox;
  const VoxelizeOptions vo = voxelizeOptions(opt);
  checkOutputPath(output, {scenePath});
  const Scene scene = loadScene(scenePath);
  Grid grid = namingScene(scenePath, [&] {
    Grid g = voxelizeScene(scene, vo);
    if (opt.fill) fillSolid(g, scene, FillOptions{vo.memoryLimitBytes, {}, {}, false});
    return g;
  });
  writeGridFile(output, scene, grid);
}

int runBatch(const Options& opt, int rank, int size) {
  using namespace vox;
  const auto start = Clock::now();
  Outcome mine;
  std::vector<std::string> scenes, outputs;
  mine.code = capture(
      [&] {
        if (!opt.bricks.empty()) fail<UsageError>("--bricks cannot be combined with --batch");
        scenes = readBatchList(opt.batch);
        outputs = batchOutputs(opt.batch, scenes, opt.output);
        if (rank == 0) {
          std::error_code ec;
          std::filesystem::create_directory(opt.output, ec);
          if (!std::filesystem::is_directory(opt.output, ec))
            fail<OutputError>(opt.output, ": cannot create the output folder");
        }
      },
      mine.message);
  int anyFailed = mine.code;
  MPI_Allreduce(MPI_IN_PLACE, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (!anyFailed) {
    ProgressBar bar("voxelizing scenes", opt.common.quiet || rank != 0);
    std::atomic<uint64_t> done{0};
    // A bad scene is that scene's failure, not the rank's: the queue goes on.
    mpi::runWorkQueue(MPI_COMM_WORLD, scenes.size(), [&](uint64_t i) {
      const auto t = Clock::now();
      std::string message;
      const int32_t code = capture([&] { voxelizeOne(opt, scenes[i], outputs[i]); }, message);
      mine.scenes.push_back({i, {code, message}});
      mine.seconds += std::chrono::duration<double>(Clock::now() - t).count();
      ++mine.items;
      bar.update(double(++done) / double(scenes.size()));
      return true;
    });
    bar.finish();
  }
  mine.peakMb = peakMemoryMb();
  const std::vector<Outcome> all = gatherOutcomes(mine, rank, size);
  int code = kExitOk;
  if (rank == 0) {
    if (all[0].code != kExitOk) {  // the list or the folder: every rank saw the same
      code = all[0].code;
      printError(all[0].message);
    } else {
      std::vector<std::pair<uint64_t, std::pair<int32_t, std::string>>> results;
      for (const auto& o : all) results.insert(results.end(), o.scenes.begin(), o.scenes.end());
      std::sort(results.begin(), results.end());
      size_t failed = 0;
      for (const auto& [i, result] : results)
        if (result.first != kExitOk) {
          ++failed;
          code = std::max(code, int(result.first));
          printError(result.second);
        }
      if (failed && !opt.common.quiet)
        std::fprintf(stderr, "vox-voxelize-mpi: %zu of %zu scenes failed\n", failed, scenes.size());
    }
    if (opt.stats) printRankStats(all, std::chrono::duration<double>(Clock::now() - start).count());
  }
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return code;
}

// Default threads per rank: the node's cores shared by the ranks on it (two ranks on two cores: one thread each).
unsigned defaultThreads() {
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &local);
  int localRanks = 1;
  MPI_Comm_size(local, &localRanks);
  MPI_Comm_free(&local);
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return std::max(1u, cores / unsigned(std::max(1, localRanks)));
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Options opt;
  CLI::App app{
      "Voxelize over Open MPI ranks: one scene into a grid set (--bricks), or a batch of scenes into one grid "
      "each (--batch). Run as mpirun -n K vox-voxelize-mpi ...",
      "vox-voxelize-mpi"};
  app.add_option("scene", opt.scene, "Input scene file (with --bricks)");
  app.add_option("--batch", opt.batch, "File listing scenes, one path a line: each becomes DIR/NAME.vgrid");
  app.add_option("-o,--output", opt.output, "Output manifest (.vgrid) with --bricks, output folder with --batch")
      ->required();
  auto* grid = app.add_option("--grid", opt.grid, "Grid dimensions NX NY NZ")->expected(3);
  auto* res = app.add_option("--res", opt.resolution, "Cells on the longest axis; cells kept as cubic as possible");
  grid->excludes(res);
  app.add_option("--bounds", opt.bounds, "Grid bounds X0 Y0 Z0 X1 Y1 Z1 (default: the scene's bounded primitives)")
      ->expected(6);
  app.add_option("--method", opt.method, "Overlap test: exact (default), sat, bbox, center")
      ->check(CLI::IsMember({"exact", "sat", "bbox", "center"}));
  app.add_flag("--fill", opt.fill,
               "Also mark the empty cells inside the surfaces as solid (with --bricks: rank 0 fills over the "
               "written bricks; the same solid cells as vox-voxelize --fill)");
  app.add_option("--bricks", opt.bricks, "Bricks BX BY BZ of the grid set (one scene)")
      ->expected(3)
      ->check(CLI::Range(1u, vox::kMaxCellsPerAxis));
  app.add_flag("--stats", opt.stats, "Print per-rank work time and peak memory on stderr (rank 0)");
  vox::cli::addCommonOptions(app, opt.common);
  app.footer(
      "Each rank uses the node's cores divided by the ranks on it unless --threads is given. Exit codes (the "
      "same on every rank): 0 ok, 1 usage, 2 bad input (a batch: some scene was bad), 3 cannot write.");
  std::optional<int> early;
  if (rank == 0) {
    early = vox::cli::parse(app, argc, argv);
  } else {
    // Only rank 0 prints help, versions and usage errors; the others parse silently to the same result.
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success&) {
      early = 0;
    } catch (const CLI::ParseError&) {
      early = vox::kExitUsage;
    }
  }
  if (!early && opt.batch.empty() == opt.scene.empty()) {
    if (rank == 0)
      std::fprintf(stderr, "vox-voxelize-mpi: error: give either SCENE with --bricks or --batch LIST (see --help)\n");
    early = vox::kExitUsage;
  }
  if (!early && opt.batch.empty() && opt.bricks.empty()) {
    if (rank == 0) std::fprintf(stderr, "vox-voxelize-mpi: error: SCENE needs --bricks BX BY BZ (see --help)\n");
    early = vox::kExitUsage;
  }
  int code = early.value_or(0);
  if (!early) {
    auto threads = vox::cli::limitThreads(opt.common.threads ? opt.common.threads : defaultThreads());
    if (provided < MPI_THREAD_SERIALIZED) {
      if (rank == 0) std::fprintf(stderr, "vox-voxelize-mpi: error: this MPI library lacks MPI_THREAD_SERIALIZED\n");
      code = vox::kExitUsage;
    } else {
      code = opt.batch.empty() ? runSet(opt, rank, size) : runBatch(opt, rank, size);
    }
  }
  MPI_Finalize();
  return code;
}
