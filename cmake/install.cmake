# What `cmake --install BUILD --prefix P` installs (issue 36): the tools, the library (libvox.a), its public headers
# (vox/...), the OpenImageIO module the library opens on first use, a CMake package (find_package(libvox CONFIG):
# libvox::vox) and a pkg-config file (libvox.pc); man pages from the tools' --help when help2man is there. cpack -G DEB
# turns the same tree into a Debian package (cmake/package.cmake). Included by the top-level CMakeLists.txt.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Headers only the library's own sources and the tools include (bit-level helpers, the tools' exit codes) stay out;
# every other header under libvox/include/vox is the public API. tests/install/ compiles each installed header alone.
set(VOX_INTERNAL_HEADERS core/varint.h core/checked_math.h core/cell_range.h core/tool.h)
file(GLOB_RECURSE vox_headers RELATIVE ${CMAKE_SOURCE_DIR}/libvox/include/vox ${CMAKE_SOURCE_DIR}/libvox/include/vox/*.h)
list(REMOVE_ITEM vox_headers ${VOX_INTERNAL_HEADERS})
foreach(header ${vox_headers})
  get_filename_component(folder ${header} DIRECTORY)
  install(FILES libvox/include/vox/${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vox/${folder} COMPONENT dev)
endforeach()

# libvox.a links CGAL (header-only here: GMP and MPFR), OpenMesh, OpenVDB, Imath and zlib privately; an installed
# static library must name them to its users, but as plain libraries, so that find_package(libvox) needs only TBB
# (no CGAL, Boost or OpenMesh headers: no public header includes them).
set(VOX_STATIC_LINK_LIBRARIES OpenMeshCore openvdb Imath gmp mpfr z)
target_link_libraries(vox INTERFACE $<INSTALL_INTERFACE:${VOX_STATIC_LINK_LIBRARIES}>)
target_include_directories(vox INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
install(TARGETS vox EXPORT libvoxTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
# The OpenImageIO module: beside the library, where oiioModule() looks (the tools find it as BIN/../LIBDIR).
install(TARGETS vox_oiio LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime)
foreach(tool vox-voxelize vox-info vox-trace vox-export vox-voxelize-mpi)
  if(TARGET ${tool})
    install(TARGETS ${tool} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  endif()
endforeach()

set(vox_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/libvox)
install(EXPORT libvoxTargets NAMESPACE libvox:: DESTINATION ${vox_cmake_dir} COMPONENT dev)
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/libvoxConfig.cmake.in ${CMAKE_BINARY_DIR}/libvoxConfig.cmake
  INSTALL_DESTINATION ${vox_cmake_dir})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/libvoxConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/libvoxConfig.cmake ${CMAKE_BINARY_DIR}/libvoxConfigVersion.cmake
  DESTINATION ${vox_cmake_dir} COMPONENT dev)

# pkg-config: a static library, so Libs names what it links; paths relative to the .pc file's own prefix.
list(TRANSFORM VOX_STATIC_LINK_LIBRARIES PREPEND "-l" OUTPUT_VARIABLE vox_pc_libs)
string(JOIN " " vox_pc_libs ${vox_pc_libs})
file(RELATIVE_PATH vox_pc_up /root/${CMAKE_INSTALL_LIBDIR}/pkgconfig /root)
configure_file(${CMAKE_SOURCE_DIR}/cmake/libvox.pc.in ${CMAKE_BINARY_DIR}/libvox.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/libvox.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)

# Man pages from each tool's --help and --version (help2man), made at build time only when help2man is installed.
find_program(VOX_HELP2MAN help2man)
if(VOX_HELP2MAN AND NOT VOX_SANITIZE AND NOT VOX_FUZZ)  # instrumented tools: no pages needed
  foreach(tool vox-voxelize vox-info vox-trace vox-export)
    add_custom_command(OUTPUT ${CMAKE_BINARY_DIR}/man/${tool}.1
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/man
      COMMAND ${VOX_HELP2MAN} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION}
              --name=${tool} --output=${CMAKE_BINARY_DIR}/man/${tool}.1 $<TARGET_FILE:${tool}>
      DEPENDS ${tool} VERBATIM)
    list(APPEND vox_man_pages ${CMAKE_BINARY_DIR}/man/${tool}.1)
  endforeach()
  add_custom_target(vox_man_pages ALL DEPENDS ${vox_man_pages})
  install(FILES ${vox_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime)
endif()

include(${CMAKE_SOURCE_DIR}/cmake/package.cmake)
