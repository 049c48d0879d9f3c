# SURFMAP_FUZZ=ON: the libFuzzer build (tests/fuzz, run by scripts/fuzz.sh).
# Clang only, in its own build directory: every target of that directory is
# compiled with libFuzzer's coverage instrumentation and ASan + UBSan, so the
# code under test (estimate, mesh, codec, the generated proto code) reports its
# coverage and its memory errors; only the harnesses link libFuzzer's main.
# Debian's prebuilt libraries (OpenSubdiv, protobuf, gRPC, abseil,
# tinyobjloader) stay uninstrumented: their coverage is not seen, their heap
# is still checked through ASan's allocator.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "SURFMAP_FUZZ=ON needs clang with libFuzzer "
                      "(CXX=clang++-14, Debian packages clang-14 libclang-rt-14-dev); "
                      "this is ${CMAKE_CXX_COMPILER_ID}. Use scripts/fuzz.sh.")
endif()
# -fno-sanitize-recover=all: UBSan stops at its first report, so libFuzzer
# sees a crash and keeps the input (by default UBSan prints and goes on).
# -UNDEBUG: assertions on (ours, and Eigen's index and size checks) whatever the
# build type.
add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                    -fno-omit-frame-pointer -UNDEBUG)
add_link_options(-fsanitize=address,undefined)
