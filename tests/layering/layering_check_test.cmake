# cmake -DSURFMAP_SOURCE_DIR=<repo> -P layering_check_test.cmake
cmake_minimum_required(VERSION 3.25)
# The layering check (cmake/Layering.cmake) on fake graphs: it passes the
# allowed edges, and names every edge that breaks the rule. Fails (exit 1) on
# the first wrong answer.
if(NOT SURFMAP_SOURCE_DIR)
  message(FATAL_ERROR "pass -DSURFMAP_SOURCE_DIR=<the repository>")
endif()
include(${SURFMAP_SOURCE_DIR}/cmake/Layering.cmake)

function(expect_clean)
  surfmap_layering_violations(bad EDGES ${ARGN})
  if(NOT bad STREQUAL "")
    message(FATAL_ERROR "allowed edges were refused:\n${bad}")
  endif()
endfunction()

function(expect_refused needle)
  surfmap_layering_violations(bad EDGES ${ARGN})
  if(bad STREQUAL "")
    message(FATAL_ERROR "a violating edge passed: ${ARGN}")
  endif()
  string(FIND "${bad}" "${needle}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the message does not name the edge (${needle}):\n${bad}")
  endif()
endfunction()

# Allowed: down the server's layers, a client on a server library, a test on
# anything, links inside one room, the top-level helper.
expect_clean(
  "surfmap_map|server/map|surfmap_mesh|server/mesh"
  "surfmap_plan|server/plan|surfmap_map|server/map"
  "surfmap_jobs|server/jobs|surfmap_storage|storage"
  "surfmap_service|server/service|surfmap_jobs|server/jobs"
  "surfmap|clients/cli|surfmap_codec|server/codec"
  "surfmap_estimate_test|server/estimate|surfmap_rig|clients/sim/rig"
  "surfmap_itest_support|tests|surfmap_rig|clients/sim/rig"
  "surfmap_storage_testing|storage/testing|surfmap_storage|storage"
  "surfmapd|server/service|surfmap_version|")

# Refused, each naming the edge: up the layers, server on clients, clients on
# test code, a directory in no room.
expect_refused("surfmap_estimate (server/estimate) links surfmap_mesh (server/mesh)"
  "surfmap_estimate|server/estimate|surfmap_mesh|server/mesh")
expect_refused("surfmap_storage (storage) links surfmap_jobs (server/jobs)"
  "surfmap_storage|storage|surfmap_jobs|server/jobs")
expect_refused("surfmap_codec (server/codec) links surfmap_helper (clients/helper)"
  "surfmap_codec|server/codec|surfmap_helper|clients/helper")
expect_refused("surfmap_plan (server/plan) links surfmap_rig (clients/sim/rig): room server/plan may link only"
  "surfmap_plan|server/plan|surfmap_rig|clients/sim/rig")
expect_refused("surfmap (clients/cli) links test code surfmap_itest_support (tests)"
  "surfmap|clients/cli|surfmap_itest_support|tests")
expect_refused("surfmap_odd (odd/place) is in no room"
  "surfmap_odd|odd/place|surfmap_base|server/base")
# Test code beside production code (a `testing` directory) may link what it
# stands in for, and nothing that ships may link it, in its room or not.
expect_clean("surfmap_storage_testing|storage/testing|surfmap_jobs|server/jobs")
expect_refused("surfmap_jobs (server/jobs) links test code surfmap_storage_testing (storage/testing)"
  "surfmap_jobs|server/jobs|surfmap_storage_testing|storage/testing")
expect_refused("surfmap_storage (storage) links test code surfmap_storage_testing (storage/testing)"
  "surfmap_storage|storage|surfmap_storage_testing|storage/testing")
# One bad edge among good ones is still found.
expect_refused("surfmap_base (server/base) links surfmap_proto (proto)"
  "surfmap_map|server/map|surfmap_mesh|server/mesh"
  "surfmap_base|server/base|surfmap_proto|proto")

message(STATUS "layering check: allowed edges pass, every violating edge is named")
