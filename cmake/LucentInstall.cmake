# Installs Lucent as a relocatable CMake package: the libraries, the public and device
# headers, the `lucent` CLI, the module embedding tool, lucent_add_programs, and
# LucentConfig.cmake / LucentConfigVersion.cmake with the targets Lucent::lucent,
# Lucent::scene, Lucent::samples (the samples' objects and their modules' objects, linked
# whole), Lucent::bench (the benchmarks, their modules' objects linked whole) and
# Lucent::lucent_embed_module. Every path in the package is relative to
# its prefix, so an installed tree may be moved.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(LUCENT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/Lucent)
set(LUCENT_PACKAGE_NEEDS_TINYOBJLOADER OFF)
if(TARGET tinyobjloader::tinyobjloader)
  set(LUCENT_PACKAGE_NEEDS_TINYOBJLOADER ON)
endif()
set(LUCENT_PACKAGE_NEEDS_OPENEXR OFF)
if(TARGET OpenEXR::OpenEXR)
  set(LUCENT_PACKAGE_NEEDS_OPENEXR ON)
endif()
set(LUCENT_PACKAGE_NEEDS_MPI ${LUCENT_HAVE_MPI})
set(LUCENT_PACKAGE_NEEDS_EMBREE OFF)  # Lucent::bench's peer
if(embree_FOUND)
  set(LUCENT_PACKAGE_NEEDS_EMBREE ON)
endif()
set(LUCENT_PACKAGE_HAS_CUDA OFF)
if(LUCENT_CUDA_INCLUDES)
  set(LUCENT_PACKAGE_HAS_CUDA ON)
endif()

install(TARGETS lucent lucent_scene lucent_embed_module lucent_samples lucent_sample_programs
                lucent_samples_package lucent_bench lucent_bench_programs lucent_bench_package
                EXPORT LucentTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  OBJECTS DESTINATION ${CMAKE_INSTALL_LIBDIR}/lucent-objects
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS lucent_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The host API and the device API (module headers include lucent/device.h; the CUDA backend
# carries its own copy of the device headers for NVRTC inside the library).
install(DIRECTORY include/lucent DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY scene DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h" PATTERN "cpu_mesh_queries.h" EXCLUDE)  # that one is internal
# The samples' headers (samples/sample.h is their API) and their program modules' text.
install(DIRECTORY samples DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")
# The benchmarks' headers (bench/rays/rays_bench.h: bench_rays_json), not their GPU kernels.
install(DIRECTORY bench DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h" PATTERN "gpu" EXCLUDE PATTERN "scenes" EXCLUDE)

install(EXPORT LucentTargets NAMESPACE Lucent:: DESTINATION ${LUCENT_CMAKE_DIR})
configure_package_config_file(cmake/LucentConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/LucentConfig.cmake INSTALL_DESTINATION ${LUCENT_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/LucentConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/LucentConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/LucentConfigVersion.cmake cmake/LucentPrograms.cmake
  DESTINATION ${LUCENT_CMAKE_DIR})
