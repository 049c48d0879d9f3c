# surfmap_add_test(NAME name SOURCES a.cc b.cc LIBS lib...)
# One GoogleTest binary registered with CTest; tests live beside the code they test.
function(surfmap_add_test)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT SURFMAP_BUILD_TESTS)
    return()
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gmock GTest::gtest GTest::gtest_main)
  # Test code gets the same warnings as the code it tests (and -Werror with
  # SURFMAP_WERROR): a warning in a test hides bugs in the test.
  target_compile_options(${T_NAME} PRIVATE ${SURFMAP_WARNINGS})
  # A test's own code (assertions, fixtures, scene set-up) is compiled -O1: it
  # halves these files' build time, and the code under test keeps -O2 in its
  # library. Tests are most of the build (docs/benchmarks.md, "Build time").
  # GCC 12's -Wmaybe-uninitialized depends on the optimisation level and at
  # -O1 misfires on moves into a std::optional holding vectors (libstdc++'s
  # _Optional_payload); library code keeps the warning at -O2.
  target_compile_options(${T_NAME} PRIVATE $<$<CONFIG:RelWithDebInfo,Release>:-O1>
                         $<$<AND:$<CONFIG:RelWithDebInfo,Release>,$<CXX_COMPILER_ID:GNU>>:-Wno-maybe-uninitialized>)
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  gtest_discover_tests(${T_NAME}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    TEST_PREFIX "${T_NAME}."
    PROPERTIES TIMEOUT ${T_TIMEOUT} LABELS "${T_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()

# surfmap_add_benchmark(NAME name SOURCES a.cc LIBS lib...)
function(surfmap_add_benchmark)
  cmake_parse_arguments(B "" "NAME" "SOURCES;LIBS" ${ARGN})
  if(NOT SURFMAP_BUILD_BENCHMARKS)
    return()
  endif()
  add_executable(${B_NAME} ${B_SOURCES})
  target_link_libraries(${B_NAME} PRIVATE ${B_LIBS} benchmark::benchmark)
endfunction()

set(SURFMAP_WARNINGS -Wall -Wextra -Wpedantic -Wno-unused-parameter)
if(SURFMAP_WERROR)
  list(APPEND SURFMAP_WARNINGS -Werror)
endif()

# surfmap_module(NAME lib DIR dir DEPS ... TEST_DEPS ...)
# A module is a folder: every foo.cc is the library, every foo_test.cc goes into
# one GoogleTest binary <lib>_test, every foo_benchmark.cc is its own benchmark.
function(surfmap_module)
  cmake_parse_arguments(M "" "NAME" "DEPS;TEST_DEPS" ${ARGN})
  file(GLOB _all CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  set(_lib_srcs "")
  set(_test_srcs "")
  set(_bench_srcs "")
  foreach(f ${_all})
    if(f MATCHES "_test\\.cc$")
      list(APPEND _test_srcs ${f})
    elseif(f MATCHES "_benchmark\\.cc$")
      list(APPEND _bench_srcs ${f})
    elseif(NOT f MATCHES "_main\\.cc$")
      list(APPEND _lib_srcs ${f})
    endif()
  endforeach()
  if(NOT _lib_srcs)  # a module still being written: headers only
    add_library(${M_NAME} INTERFACE)
    target_include_directories(${M_NAME} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${M_NAME} INTERFACE ${M_DEPS})
  else()
    add_library(${M_NAME} ${_lib_srcs})
    target_include_directories(${M_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(${M_NAME} PUBLIC ${M_DEPS})
    target_compile_options(${M_NAME} PRIVATE ${SURFMAP_WARNINGS})
  endif()
  if(_test_srcs)
    surfmap_add_test(NAME ${M_NAME}_test SOURCES ${_test_srcs} LIBS ${M_NAME} ${M_TEST_DEPS})
  endif()
  foreach(b ${_bench_srcs})
    get_filename_component(_bn ${b} NAME_WE)
    surfmap_add_benchmark(NAME ${_bn} SOURCES ${b} LIBS ${M_NAME} ${M_TEST_DEPS})
  endforeach()
endfunction()
