# The viewer page of vox-export (issue 25; DESIGN.md "Viewer page"), included by the top-level CMakeLists.txt.
# viewer/src and three.js are bundled at build time by viewer/build.mjs (esbuild) into a C++ source linked into
# libvox, which embeds it into every page. npm ci installs the packages pinned in viewer/package-lock.json into
# BUILD/viewer/node_modules (taken from npm's cache when they are there: --prefer-offline); nothing is written into
# the source tree and nothing built goes into git.
option(VOX_VIEWER "Build the viewer page of vox-export (-o OUT.html); needs Node.js and npm at build time" ON)
# The page's data is deflated (zlib, which Debian's OpenVDB and OpenImageIO already bring).
find_package(ZLIB REQUIRED)
target_link_libraries(vox PRIVATE $<BUILD_INTERFACE:ZLIB::ZLIB>)
if(NOT VOX_VIEWER)
  return()
endif()
find_program(VOX_NODE node)
find_program(VOX_NPM npm)
if(NOT VOX_NODE OR NOT VOX_NPM)
  message(FATAL_ERROR "the viewer page (vox-export -o OUT.html) is built with Node.js and npm, which were not "
                      "found: install them (scripts/install-deps.sh) or configure with -DVOX_VIEWER=OFF")
endif()
set(vox_viewer_build ${CMAKE_BINARY_DIR}/viewer)
file(MAKE_DIRECTORY ${vox_viewer_build})
file(GLOB vox_viewer_sources CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/viewer/src/*.js)
add_custom_command(
  OUTPUT ${vox_viewer_build}/node_modules/.package-lock.json
  COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/viewer/package.json ${CMAKE_SOURCE_DIR}/viewer/package-lock.json
          ${vox_viewer_build}
  COMMAND ${VOX_NPM} ci --prefer-offline --no-audit --no-fund --loglevel=error
  DEPENDS ${CMAKE_SOURCE_DIR}/viewer/package.json ${CMAKE_SOURCE_DIR}/viewer/package-lock.json
  WORKING_DIRECTORY ${vox_viewer_build}
  COMMENT "npm ci (viewer/package-lock.json)"
  VERBATIM)
add_custom_command(
  OUTPUT ${vox_viewer_build}/viewer_script.cpp ${vox_viewer_build}/viewer_script.js
  COMMAND ${VOX_NODE} ${CMAKE_SOURCE_DIR}/viewer/build.mjs ${vox_viewer_build}
  DEPENDS ${vox_viewer_sources} ${CMAKE_SOURCE_DIR}/viewer/build.mjs ${vox_viewer_build}/node_modules/.package-lock.json
  WORKING_DIRECTORY ${vox_viewer_build}
  COMMENT "Bundling the viewer page's script (viewer/build.mjs)"
  VERBATIM)
target_sources(vox PRIVATE ${vox_viewer_build}/viewer_script.cpp)
set_property(SOURCE ${CMAKE_SOURCE_DIR}/libvox/src/export/viewer_page.cpp APPEND PROPERTY COMPILE_DEFINITIONS
             VOX_HAVE_VIEWER_SCRIPT)

if(VOX_TESTS)
  # The page in headless Chromium (tests/viewer/, driven by playwright-core from the same node_modules). Exit 77:
  # skipped (no chromium); CI installs it (scripts/install-deps.sh --clients).
  file(GLOB vox_viewer_tests CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/viewer/*_test.mjs)
  foreach(script ${vox_viewer_tests})
    get_filename_component(name ${script} NAME_WE)
    add_test(NAME viewer_${name} COMMAND ${VOX_NODE} ${script} ${CMAKE_BINARY_DIR} ${CMAKE_SOURCE_DIR})
    set_tests_properties(viewer_${name} PROPERTIES SKIP_RETURN_CODE 77 COST 60 ENVIRONMENT "VOX_SEED_DIR=${VOX_SEED_DIR}")
  endforeach()
endif()
