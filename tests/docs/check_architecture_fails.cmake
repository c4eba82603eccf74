# The check of docs/architecture.md (check_architecture.cmake) must fail on a header that no row
# names: a copy of the page and of include/ffsr gains an unnamed header, and the check, run on the
# copy, must fail naming it. Run by ctest (case `docs_architecture_unnamed_header`):
#   cmake -DFFSR_SOURCE_DIR=<repo> -DWORK_DIR=<scratch folder> -P check_architecture_fails.cmake
if(NOT FFSR_SOURCE_DIR OR NOT WORK_DIR)
  message(FATAL_ERROR "check_architecture_fails: pass -DFFSR_SOURCE_DIR=<the repository> -DWORK_DIR=<folder>")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}/include")
file(COPY "${FFSR_SOURCE_DIR}/docs" DESTINATION "${WORK_DIR}")
file(COPY "${FFSR_SOURCE_DIR}/include/ffsr" DESTINATION "${WORK_DIR}/include")
# the paths of "Where it goes" outside include/ must exist in the copy too
foreach(dir src python tests robots scripts bench fuzz examples cmake)
  if(EXISTS "${FFSR_SOURCE_DIR}/${dir}")
    file(CREATE_LINK "${FFSR_SOURCE_DIR}/${dir}" "${WORK_DIR}/${dir}" SYMBOLIC)
  endif()
endforeach()
execute_process(COMMAND "${CMAKE_COMMAND}" -DFFSR_SOURCE_DIR=${WORK_DIR}
                        -P "${CMAKE_CURRENT_LIST_DIR}/check_architecture.cmake"
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "check_architecture fails on the unchanged copy:\n${out}${err}")
endif()
file(WRITE "${WORK_DIR}/include/ffsr/algorithm/unnamed_algorithm.hpp" "#pragma once\n")
execute_process(COMMAND "${CMAKE_COMMAND}" -DFFSR_SOURCE_DIR=${WORK_DIR}
                        -P "${CMAKE_CURRENT_LIST_DIR}/check_architecture.cmake"
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(status EQUAL 0)
  message(FATAL_ERROR "check_architecture passed a tree with a header no row names")
endif()
if(NOT err MATCHES "include/ffsr/algorithm/unnamed_algorithm.hpp is named by no row")
  message(FATAL_ERROR "check_architecture failed without naming the unnamed header:\n${err}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
message(STATUS "check_architecture fails on a header no row names, as it must")
