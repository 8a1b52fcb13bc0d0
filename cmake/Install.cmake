# `cmake --install build --prefix P`: the static library, its public headers, the `bvc3d` program, and
# a CMake package, so that another project builds on bvc3d with
#   find_package(bvc3d REQUIRED)   # CMAKE_PREFIX_PATH=P
#   target_link_libraries(app PRIVATE bvc3d::bvc3d)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The same name inside this build as for an installed package, for projects that add_subdirectory() us.
add_library(bvc3d::bvc3d ALIAS bvc3d)

# Kernels and internals: only the library's own sources include them, so they are not installed.
# A public header that includes one of these is a bug (test/install/run.sh compiles each public header
# on its own against the installed tree).
set(BVC3D_PRIVATE_HEADERS
  bvc3d/bvc/bvc_kernels.hpp
  bvc3d/bvc/pruned_sums.hpp
  bvc3d/place/place_kernels.hpp
  bvc3d/navigation/adjacency_kernels.hpp
  bvc3d/core/simd.hpp
  bvc3d/analysis/point_grid.hpp
  bvc3d/analysis/cosine_kernels.hpp
  bvc3d/recorder/hdf5_io.hpp
  bvc3d/recording/file_io.hpp
  bvc3d/recording/parsing.hpp
  bvc3d/recording/cloud_builder.hpp
  bvc3d/experiment/mpi_coordinator.hpp)
# The list, for test/install/run.sh to check that none of them is installed.
string(REPLACE ";" "\n" BVC3D_PRIVATE_LINES "${BVC3D_PRIVATE_HEADERS}")
file(WRITE ${PROJECT_BINARY_DIR}/private-headers.txt "${BVC3D_PRIVATE_LINES}\n")

# Every other header under src/bvc3d is public: a new header is installed unless listed above.
file(GLOB_RECURSE BVC3D_PUBLIC_HEADERS CONFIGURE_DEPENDS RELATIVE ${PROJECT_SOURCE_DIR}/src
     ${PROJECT_SOURCE_DIR}/src/bvc3d/*.hpp)
list(REMOVE_ITEM BVC3D_PUBLIC_HEADERS ${BVC3D_PRIVATE_HEADERS})
foreach(header ${BVC3D_PUBLIC_HEADERS})
  get_filename_component(folder ${header} DIRECTORY)
  install(FILES src/${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/${folder})
endforeach()

install(TARGETS bvc3d EXPORT bvc3dTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS bvc3d_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

set(BVC3D_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/bvc3d)
install(EXPORT bvc3dTargets NAMESPACE bvc3d:: DESTINATION ${BVC3D_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bvc3dConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/bvc3dConfig.cmake INSTALL_DESTINATION ${BVC3D_CMAKE_DIR})
# 0.x releases may change the API between minor versions, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bvc3dConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bvc3dConfig.cmake ${PROJECT_BINARY_DIR}/bvc3dConfigVersion.cmake
        DESTINATION ${BVC3D_CMAKE_DIR})
