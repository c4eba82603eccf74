# The layers of include/ffsr: each folder includes only folders at or below it in the table below
# (docs/library.md draws it). Run by ctest (case `layers`):
#   cmake -DFFSR_INCLUDE_DIR=<include/ffsr> -P check_layers.cmake
# Every header's `#include "ffsr/<folder>/..."` (and "ffsr/<name>.hpp" at the top) is checked; a
# folder missing from the table fails the check, so that a new folder is placed on purpose.

# One layer per entry, the lowest first; names in one entry are one layer. A top-level header
# "ffsr/<name>.hpp" counts as the folder <name>: errors.hpp lies at the bottom, the umbrella header
# ffsr.hpp at the top (it gathers the Eigen-only parts of every folder).
set(FFSR_LAYERS
  "errors detail"
  "spatial"
  "model"
  "contact"
  "algorithm"
  "geometry"
  "parsers"
  "simulate"
  "uncertainty"
  "optimize"
  "control"
  "scenario"
  "jobs"
  "ffsr"
)
if(NOT FFSR_INCLUDE_DIR)
  message(FATAL_ERROR "check_layers: pass -DFFSR_INCLUDE_DIR=<include/ffsr>")
endif()

# sets <prefix>_<name> to the rank of its entry in the list `table` (entries lowest first, the names
# of one entry separated by spaces share its rank)
macro(rank_entries table prefix)
  set(rank 0)
  foreach(entry IN LISTS ${table})
    string(REPLACE " " ";" names "${entry}")
    foreach(name IN LISTS names)
      set(${prefix}_${name} ${rank})
    endforeach()
    math(EXPR rank "${rank} + 1")
  endforeach()
endmacro()

rank_entries(FFSR_LAYERS LAYER)

# the layer name of a path relative to include/ffsr: its first component, or the file's name without
# .hpp at the top
function(layer_name_of path out)
  if(path MATCHES "^([a-z_]+)/")
    set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
  elseif(path MATCHES "^([a-z_]+)\\.hpp$")
    set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
  else()
    set(${out} "" PARENT_SCOPE)
  endif()
endfunction()

set(errors "")
file(GLOB_RECURSE headers RELATIVE "${FFSR_INCLUDE_DIR}" "${FFSR_INCLUDE_DIR}/*.hpp" "${FFSR_INCLUDE_DIR}/*.hxx")
list(SORT headers)
foreach(h IN LISTS headers)
  layer_name_of("${h}" own)
  if(NOT DEFINED LAYER_${own})
    list(APPEND errors "${h}: its folder '${own}' is not in the layers table of ${CMAKE_CURRENT_LIST_FILE}")
    continue()
  endif()
  file(STRINGS "${FFSR_INCLUDE_DIR}/${h}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]ffsr/")
  foreach(line IN LISTS lines)
    string(REGEX MATCH "ffsr/([^\">]+)" _ "${line}")
    set(target "${CMAKE_MATCH_1}")
    layer_name_of("${target}" dep)
    if(NOT DEFINED LAYER_${dep})
      list(APPEND errors "${h}: includes ffsr/${target}, whose folder '${dep}' is not in the layers table")
    elseif(LAYER_${dep} GREATER LAYER_${own})
      list(APPEND errors "${h} (layer of ${own}) includes ffsr/${target}, a layer above it (that of ${dep})")
    endif()
  endforeach()
endforeach()

# Within the floor jobs/: the order of its files, the lowest first (docs/architecture.md draws it). A
# file includes only files of its own entry or of an entry below it: an entry is a header and the bodies
# it includes at its end (which include it back), so that the jobs depend on each other one way (the
# main job knows nothing of the detumble job, which plans the main job's runs; the whole capture
# composes both). A jobs/ file missing from the table fails the check; an include of a file of a higher
# entry is a cycle or on its way to one, and fails it too.
set(FFSR_JOBS_ORDER
  "detail/json_values"
  "scenario_clearance"
  "detail/detumble_result"
  "detail/post_capture"
  "detail/post_capture_front"
  "scenario_run detail/scenario_run detail/base_disturbance_json detail/scenario_series detail/result_json"
  "inspect map"
  "contact"
  "detumble"
  "closed_loop pareto robust detail/robust"
  "whole_capture"
)
rank_entries(FFSR_JOBS_ORDER JOBS)
foreach(h IN LISTS headers)
  if(NOT h MATCHES "^jobs/(.+)\\.(hpp|hxx)$")
    continue()
  endif()
  set(own "${CMAKE_MATCH_1}")
  if(NOT DEFINED JOBS_${own})
    list(APPEND errors
         "${h}: not in the order of the jobs/ files (FFSR_JOBS_ORDER in ${CMAKE_CURRENT_LIST_FILE})")
    continue()
  endif()
  file(STRINGS "${FFSR_INCLUDE_DIR}/${h}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]ffsr/jobs/")
  foreach(line IN LISTS lines)
    string(REGEX MATCH "ffsr/jobs/([^\">]+)\\.(hpp|hxx)" _ "${line}")
    set(dep "${CMAKE_MATCH_1}")
    if(NOT DEFINED JOBS_${dep})
      list(APPEND errors "${h}: includes ffsr/jobs/${dep}, which is not in the order of the jobs/ files")
    elseif(JOBS_${dep} GREATER JOBS_${own})
      list(APPEND errors "${h} includes ffsr/jobs/${dep}, a file above it in the order of the jobs/ files "
                         "(FFSR_JOBS_ORDER): the two would depend on each other")
    endif()
  endforeach()
endforeach()

list(LENGTH headers count)
if(errors)
  string(REPLACE ";" "\n  " text "${errors}")
  message(FATAL_ERROR "layers: ${count} headers, includes against the layers:\n  ${text}")
endif()
message(STATUS "layers: ${count} headers, every include at or below its folder's layer, jobs/ in order")
