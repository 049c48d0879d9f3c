# Every dependency comes from a Debian 12 package (see scripts/install-deps.sh).
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 CONFIG REQUIRED)
find_package(absl CONFIG REQUIRED)
find_package(nlohmann_json 3.10 CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(spdlog CONFIG REQUIRED)
find_package(SQLite3 REQUIRED)
find_package(OpenSSL REQUIRED)  # constant-time token comparison (libcrypto)
find_package(tinyobjloader CONFIG REQUIRED)
find_package(meshoptimizer CONFIG REQUIRED)
find_package(Protobuf REQUIRED)
find_package(gRPC CONFIG REQUIRED)
# glTF export of maps (server/haptics): Debian's libtinygltf-dev ships it as a shared library.
find_package(TinyGLTF CONFIG REQUIRED)

# Debian's OpenSubdiv CMake config references libosdCPU.a, which the package does
# not ship (see docs/architecture.md, "Build notes"): locate the shared library by hand.
find_library(OSD_CPU_LIBRARY osdCPU REQUIRED)
find_path(OSD_INCLUDE_DIR opensubdiv/far/topologyRefiner.h REQUIRED)
add_library(OpenSubdiv::osdCPU SHARED IMPORTED)
set_target_properties(OpenSubdiv::osdCPU PROPERTIES
  IMPORTED_LOCATION "${OSD_CPU_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${OSD_INCLUDE_DIR}")

# stb (stb_image_write for PNG output): header-only use, implementation compiled once.
find_path(STB_INCLUDE_DIR stb_image_write.h PATH_SUFFIXES stb REQUIRED)

if(SURFMAP_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(SURFMAP_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
