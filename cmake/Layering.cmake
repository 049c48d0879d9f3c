# The layering rule (stated in the top-level CMakeLists.txt) as data, and the
# configure-time check that enforces it.
#
# A "room" is a directory of the source tree; every target belongs to the
# room of its SOURCE_DIR (the longest matching prefix in SURFMAP_ROOMS). A room
# may link only the rooms it lists in SURFMAP_ROOM_MAY_LINK_<room> (and
# itself); "*" means any room but tests. Test code may link anything: targets
# under tests/ and every *_test / *_benchmark target.
#
# Only links between two targets of this project are checked (imported
# targets: abseil, gRPC, Eigen... are outside the rule). Both the link of a
# target's own code (LINK_LIBRARIES) and what it passes on to its users
# (INTERFACE_LINK_LIBRARIES) are walked.
#
# Pure functions (no targets needed) so that tests/layering/ can run them on a
# fake graph with `cmake -P` and prove the check fires.

# Rooms, in any order: the longest matching prefix wins.
set(SURFMAP_ROOMS
  server/base server/estimate server/geometry server/frames server/mesh server/map server/plan server/codec
  server/haptics storage server/jobs server/service proto clients tests)

set(SURFMAP_ROOM_MAY_LINK_server/base "")
set(SURFMAP_ROOM_MAY_LINK_server/estimate server/base)
set(SURFMAP_ROOM_MAY_LINK_proto "")
set(SURFMAP_ROOM_MAY_LINK_server/geometry "")
set(SURFMAP_ROOM_MAY_LINK_server/mesh server/base server/estimate server/geometry)
set(SURFMAP_ROOM_MAY_LINK_server/frames server/base server/estimate)
set(SURFMAP_ROOM_MAY_LINK_server/map server/base server/estimate server/mesh)
set(SURFMAP_ROOM_MAY_LINK_server/plan server/base server/estimate server/geometry server/mesh server/map)
set(SURFMAP_ROOM_MAY_LINK_server/codec server/base server/estimate server/frames proto)
set(SURFMAP_ROOM_MAY_LINK_server/haptics server/base server/estimate server/geometry server/codec proto)
set(SURFMAP_ROOM_MAY_LINK_storage server/base)
set(SURFMAP_ROOM_MAY_LINK_server/jobs
  server/base server/estimate server/frames server/mesh server/map server/plan server/codec storage)
set(SURFMAP_ROOM_MAY_LINK_server/service
  server/base server/estimate server/frames server/mesh server/map server/plan server/codec server/haptics storage server/jobs proto)
set(SURFMAP_ROOM_MAY_LINK_clients "*")
set(SURFMAP_ROOM_MAY_LINK_tests "*")

# Edges that break the rule today and are on their way out, "from-room|to-room",
# each with the reason in a comment. Empty is the goal.
set(SURFMAP_LAYERING_EXCEPTIONS "")

# surfmap_room_of(<relative dir> <out var>): the room of a directory relative
# to the source root ("" when it is in none: the top level, cmake/, ...).
function(surfmap_room_of dir out)
  set(best "")
  string(LENGTH "" best_len)
  foreach(room IN LISTS SURFMAP_ROOMS)
    if(dir STREQUAL room OR dir MATCHES "^${room}/")
      string(LENGTH "${room}" len)
      if(len GREATER best_len)
        set(best ${room})
        set(best_len ${len})
      endif()
    endif()
  endforeach()
  set(${out} "${best}" PARENT_SCOPE)
endfunction()

# surfmap_is_test_target(<name> <relative dir> <out var>): tests, benchmarks,
# and test helpers beside the code they stand in for (a `testing` directory,
# e.g. storage/testing's fault-injecting store).
function(surfmap_is_test_target name dir out)
  if(name MATCHES "_(test|benchmark)$" OR dir STREQUAL "tests" OR dir MATCHES "^tests/"
     OR dir MATCHES "(^|/)testing(/|$)")
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
endfunction()

# surfmap_layering_violations(<out var> EDGES <from-target>|<from-dir>|<to-target>|<to-dir> ...)
# Dirs relative to the source root. Sets <out var> to one line per edge that
# breaks the rule, naming both targets, their directories and the rooms the
# linking one may use.
function(surfmap_layering_violations out)
  cmake_parse_arguments(L "" "" "EDGES" ${ARGN})
  set(lines "")
  foreach(edge IN LISTS L_EDGES)
    string(REPLACE "|" ";" parts "${edge}")
    list(GET parts 0 from)
    list(GET parts 1 from_dir)
    list(GET parts 2 to)
    list(GET parts 3 to_dir)
    surfmap_is_test_target(${from} "${from_dir}" from_is_test)
    if(from_is_test)
      continue()
    endif()
    surfmap_room_of("${from_dir}" from_room)
    surfmap_room_of("${to_dir}" to_room)
    # A directory in no room is an error: a new folder says where it stands.
    # The top level itself (surfmap_version) is no room and may be used by all.
    if(from_room STREQUAL "" AND NOT from_dir STREQUAL "")
      string(APPEND lines "  ${from} (${from_dir}) is in no room: add its directory to SURFMAP_ROOMS\n")
      continue()
    elseif(to_room STREQUAL "" AND NOT to_dir STREQUAL "")
      string(APPEND lines "  ${to} (${to_dir}), linked by ${from}, is in no room: add its directory to SURFMAP_ROOMS\n")
      continue()
    endif()
    surfmap_is_test_target(${to} "${to_dir}" to_is_test)
    if(to_is_test)
      # Whatever the rooms: code that ships never links test code.
      string(APPEND lines "  ${from} (${from_dir}) links test code ${to} (${to_dir})\n")
      continue()
    elseif(from_room STREQUAL "" OR to_room STREQUAL "" OR from_room STREQUAL to_room)
      continue()  # the top-level helper, and links inside a room
    endif()
    set(allowed ${SURFMAP_ROOM_MAY_LINK_${from_room}})
    if("${from_room}|${to_room}" IN_LIST SURFMAP_LAYERING_EXCEPTIONS)
      continue()
    elseif(allowed STREQUAL "*" AND NOT to_room STREQUAL "tests")
      continue()
    elseif(to_room IN_LIST allowed)
      continue()
    endif()
    if(allowed STREQUAL "")
      set(allowed_text "nothing else")
    else()
      string(REPLACE ";" ", " allowed_text "${allowed}")
    endif()
    string(APPEND lines
      "  ${from} (${from_dir}) links ${to} (${to_dir}): room ${from_room} may link only ${allowed_text}\n")
  endforeach()
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()

# The targets defined in <dir> and every directory below it.
function(_surfmap_targets_below dir out)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    _surfmap_targets_below(${sub} sub_targets)
    list(APPEND targets ${sub_targets})
  endforeach()
  set(${out} "${targets}" PARENT_SCOPE)
endfunction()

# surfmap_check_layering([ROOT <dir>]): walks every target of this project and
# stops the configuration (FATAL_ERROR) naming each edge that breaks the rule.
# Called at the end of the top-level CMakeLists.txt, when every target exists.
function(surfmap_check_layering)
  cmake_parse_arguments(C "" "ROOT" "" ${ARGN})
  if(NOT C_ROOT)
    set(C_ROOT ${PROJECT_SOURCE_DIR})
  endif()
  _surfmap_targets_below(${C_ROOT} targets)
  set(edges "")
  set(unreadable "")
  foreach(t IN LISTS targets)
    get_target_property(t_src ${t} SOURCE_DIR)
    file(RELATIVE_PATH t_dir ${C_ROOT} ${t_src})
    set(deps "")
    get_target_property(type ${t} TYPE)
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(own ${t} LINK_LIBRARIES)
      if(own)
        list(APPEND deps ${own})
      endif()
    endif()
    get_target_property(passed ${t} INTERFACE_LINK_LIBRARIES)
    if(passed)
      list(APPEND deps ${passed})
    endif()
    foreach(d IN LISTS deps)
      # Static libraries pass private links on as $<LINK_ONLY:x>.
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" d "${d}")
      if(d MATCHES "^\\$<")
        # Its target is known only at generation time: a link the check
        # could not see would pass unchecked.
        list(APPEND unreadable "  ${t} (${t_dir}) links through ${d}\n")
        continue()
      elseif(NOT TARGET ${d})
        continue()  # plain library files and flags
      endif()
      get_target_property(aliased ${d} ALIASED_TARGET)
      if(aliased)
        set(d ${aliased})
      endif()
      get_target_property(imported ${d} IMPORTED)
      if(imported)
        continue()
      endif()
      get_target_property(d_src ${d} SOURCE_DIR)
      file(RELATIVE_PATH d_dir ${C_ROOT} ${d_src})
      list(APPEND edges "${t}|${t_dir}|${d}|${d_dir}")
    endforeach()
  endforeach()
  if(unreadable)
    string(REPLACE ";" "" unreadable "${unreadable}")
    message(FATAL_ERROR "surfmap layering: links the check cannot read (use the target's name):\n${unreadable}")
  endif()
  list(REMOVE_DUPLICATES edges)
  surfmap_layering_violations(bad EDGES ${edges})
  if(bad)
    message(FATAL_ERROR "surfmap layering rule broken (see the top-level CMakeLists.txt):\n${bad}")
  endif()
  list(LENGTH edges n)
  message(STATUS "surfmap layering: ${n} links between surfmap targets follow the rule")
endfunction()
