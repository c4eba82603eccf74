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

set(rank 0)
foreach(entry IN LISTS FFSR_LAYERS)
  string(REPLACE " " ";" names "${entry}")
  foreach(name IN LISTS names)
    set(LAYER_${name} ${rank})
  endforeach()
  math(EXPR rank "${rank} + 1")
endforeach()

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

list(LENGTH headers count)
if(errors)
  string(REPLACE ";" "\n  " text "${errors}")
  message(FATAL_ERROR "layers: ${count} headers, includes against the layers:\n  ${text}")
endif()
message(STATUS "layers: ${count} headers, every include at or below its folder's layer")
