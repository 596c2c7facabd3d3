#include "io/oiio_module.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "vox/core/error.h"

namespace vox {

namespace {

// Next to the running executable (the tools and the tests), or one folder up (the fuzz targets and benchmarks of the
// build's subfolders), or in the library folder of an installed tree (BIN/../LIBDIR, wherever the tree was installed,
// then the prefix the build was configured with: cmake/install.cmake); else the dynamic linker's own search
// (LD_LIBRARY_PATH), for programs linked elsewhere.
const OiioModule* openModule() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::string besideSelf = ec ? std::string() : (self.parent_path() / "libvox_oiio.so").string();
  void* handle = nullptr;
  if (!ec) {
    const std::filesystem::path bin = self.parent_path();
    for (const auto& folder : {bin, bin.parent_path(), bin.parent_path() / VOX_INSTALL_LIBDIR})
      if (!handle) handle = ::dlopen((folder / "libvox_oiio.so").c_str(), RTLD_NOW | RTLD_LOCAL);
  }
  if (!handle) handle = ::dlopen(VOX_INSTALL_FULL_LIBDIR "/libvox_oiio.so", RTLD_NOW | RTLD_LOCAL);
  if (!handle) handle = ::dlopen("libvox_oiio.so", RTLD_NOW | RTLD_LOCAL);
  if (!handle) fail<Error>("cannot load the OpenImageIO module ", besideSelf, ": ", ::dlerror());
  using Entry = const OiioModule* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "vox_oiio_module"));
  const OiioModule* m = entry ? entry() : nullptr;
  if (!m || m->version != kOiioModuleVersion)
    fail<Error>(besideSelf, ": an OpenImageIO module of another libvox build (rebuild libvox_oiio.so)");
  return m;  // never closed: OpenImageIO keeps threads and caches for the life of the process
}

}  // namespace

const OiioModule& oiioModule() {
  static std::once_flag once;
  static const OiioModule* module = nullptr;
  std::call_once(once, [] { module = openModule(); });
  return *module;
}

}  // namespace vox
