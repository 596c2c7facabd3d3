# cpack -G DEB (in the build folder): a Debian package of what cmake/install.cmake installs, under /usr. Its Depends
# are the runtime libraries dpkg-shlibdeps finds in the tools and the OpenImageIO module; building a program against
# the static library also needs the development packages in Recommends (the link line of libvox.pc).
set(CPACK_PACKAGE_NAME libvox)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "libvox developers <libvox@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "exact voxelization and exact grid ray tracing: tools, library, headers")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS
  "libtbb-dev, libopenmesh-dev, libopenvdb-dev, libimath-dev, libgmp-dev, libmpfr-dev, zlib1g-dev, pkg-config")
set(CPACK_GENERATOR DEB)
include(CPack)
