# ffsr_add_scenario_test(NAME SCENARIO BASELINE [RTOL r] [ATOL a] [COMMAND exe] [ARGS ...])
#
# Registers a ctest case that runs
#   ffsr-optimize --config SCENARIO --expect BASELINE [--rtol r] [--atol a] [ARGS ...]
# which fails (exit 4) when a number of the result moved away from the stored one, and prints one
# line per moved value ("path: stored X, now Y"; `ctest --output-on-failure` shows them). SCENARIO
# and BASELINE are relative to the calling CMakeLists.txt. Write or regenerate a baseline with
#   ffsr-optimize --config SCENARIO --json BASELINE
# The command is the imported target ffsr::ffsr-optimize of the installed package (or the
# ffsr-optimize target of the ffsr build tree); COMMAND overrides it. Included by ffsrConfig.cmake.
function(ffsr_add_scenario_test name scenario baseline)
  cmake_parse_arguments(ARG "" "RTOL;ATOL;COMMAND" "ARGS" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "ffsr_add_scenario_test(${name}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT ARG_COMMAND)
    if(TARGET ffsr::ffsr-optimize)
      set(ARG_COMMAND $<TARGET_FILE:ffsr::ffsr-optimize>)
    else()
      message(FATAL_ERROR "ffsr_add_scenario_test(${name}): no ffsr::ffsr-optimize target (ffsr was installed "
                          "without its command, FFSR_BUILD_CLI=OFF); pass COMMAND <path to ffsr-optimize>")
    endif()
  endif()
  get_filename_component(scenario "${scenario}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(baseline "${baseline}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(args --config "${scenario}" --expect "${baseline}" --quiet)
  if(DEFINED ARG_RTOL)
    list(APPEND args --rtol "${ARG_RTOL}")
  endif()
  if(DEFINED ARG_ATOL)
    list(APPEND args --atol "${ARG_ATOL}")
  endif()
  add_test(NAME ${name} COMMAND ${ARG_COMMAND} ${args} ${ARG_ARGS})
  set_tests_properties(${name} PROPERTIES LABELS ffsr_scenario)
endfunction()
