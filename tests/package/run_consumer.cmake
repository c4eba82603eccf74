# ctest case package_consumer: install the built ffsr into a fresh prefix, then configure, build and
# run the consumer project tests/package against that prefix only, as a user would; finally
# configure it once more with urdfdom and SUNDIALS hidden, where find_package(ffsr) must give
# ffsr::ffsr alone (a user of the dynamics needs only Eigen). It also runs the installed command on
# the installed scenario share/ffsr/robots/paper_7dof_position.toml. With -DFFSR_SOURCE_DIR it also
# registers robots/paper_3dof.toml with ffsr_add_scenario_test against a copy of its stored
# baseline and runs ctest twice: it must pass, then fail naming the value moved in the baseline.
#
#   cmake -DFFSR_BINARY_DIR=<ffsr build dir> -DCONSUMER_SOURCE_DIR=<tests/package>
#         -DWORK_DIR=<scratch dir> [-DCONFIG=Release] [-DGENERATOR=Ninja]
#         [-DCXX_COMPILER=/usr/bin/c++] -P run_consumer.cmake
#
# The scratch dir is wiped first. Fails (message(FATAL_ERROR), non-zero exit) on any step.
cmake_minimum_required(VERSION 3.16)

foreach(var FFSR_BINARY_DIR CONSUMER_SOURCE_DIR WORK_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "run_consumer.cmake: -D${var}=... is required")
  endif()
endforeach()

set(prefix "${WORK_DIR}/prefix")
set(build "${WORK_DIR}/build")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "package consumer: ${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

# 1. install
set(config_args)
if(CONFIG)
  set(config_args --config "${CONFIG}")
endif()
run_step("cmake --install" "${CMAKE_COMMAND}" --install "${FFSR_BINARY_DIR}" --prefix "${prefix}" ${config_args})
file(GLOB_RECURSE config_file "${prefix}/*/ffsrConfig.cmake")
if(NOT config_file)
  message(FATAL_ERROR "package consumer: no ffsrConfig.cmake under ${prefix}")
endif()

# 1b. the installed command on an installed scenario: share/ffsr/robots/paper_7dof_position.toml
#     names its URDF relative to itself, so it must resolve inside the installed tree. Run from the
#     scratch folder (not the source tree), without the global search to keep it short; the
#     optimized run's M_ie must be ffsr's Table 7 value (2.7134 kg, as in the stored baseline).
set(installed_scenario "${prefix}/share/ffsr/robots/paper_7dof_position.toml")
if(NOT EXISTS "${installed_scenario}" OR NOT EXISTS "${prefix}/share/ffsr/robots/paper_7dof.urdf")
  message(FATAL_ERROR "package consumer: cmake --install did not put robots/ under ${prefix}/share/ffsr/robots")
endif()
file(GLOB installed_cli "${prefix}/bin/ffsr-optimize" "${prefix}/bin/ffsr-optimize.exe")
if(installed_cli)
  list(GET installed_cli 0 installed_cli)
  execute_process(COMMAND "${installed_cli}" --config "${installed_scenario}" --global=false --quiet
                          --json "${WORK_DIR}/installed_run.json"
                  WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "package consumer: the installed ffsr-optimize on ${installed_scenario} failed (${rc}):\n${out}\n${err}")
  endif()
  file(READ "${WORK_DIR}/installed_run.json" run_json)
  string(JSON m_ie GET "${run_json}" optimized integrated_effective_mass)
  if(NOT m_ie MATCHES "^2\\.713")
    message(FATAL_ERROR "package consumer: installed scenario gave M_ie = ${m_ie} kg, expected 2.713 kg")
  endif()
  message(STATUS "installed ffsr-optimize on share/ffsr/robots/paper_7dof_position.toml: M_ie ${m_ie} kg")
else()
  message(STATUS "ffsr was installed without its command (FFSR_BUILD_CLI=OFF): installed scenario not run")
endif()

# 2. configure: only the fresh prefix, no package registry, the same generator and compiler
set(configure_args -S "${CONSUMER_SOURCE_DIR}" "-DCMAKE_PREFIX_PATH=${prefix}"
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON)
if(GENERATOR)
  list(APPEND configure_args -G "${GENERATOR}")
endif()
if(CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
if(CONFIG)
  list(APPEND configure_args "-DCMAKE_BUILD_TYPE=${CONFIG}")
endif()
set(scenario_args)
if(FFSR_SOURCE_DIR)
  configure_file("${FFSR_SOURCE_DIR}/tests/data/baselines/paper_3dof.json" "${WORK_DIR}/baseline.json" COPYONLY)
  set(scenario_args "-DCONSUMER_SCENARIO=${FFSR_SOURCE_DIR}/robots/paper_3dof.toml"
                    "-DCONSUMER_BASELINE=${WORK_DIR}/baseline.json")
endif()
run_step("configuring the consumer" "${CMAKE_COMMAND}" ${configure_args} ${scenario_args} -B "${build}")
file(STRINGS "${build}/CMakeCache.txt" ffsr_dir REGEX "^ffsr_DIR:")
string(REGEX REPLACE "^ffsr_DIR:[A-Z]*=" "" ffsr_dir "${ffsr_dir}")
file(REAL_PATH "${prefix}" real_prefix)
file(REAL_PATH "${ffsr_dir}" real_ffsr_dir)
string(FIND "${real_ffsr_dir}/" "${real_prefix}/" at)
if(NOT at EQUAL 0)
  message(FATAL_ERROR "package consumer: found ffsr in '${ffsr_dir}', not in the install prefix ${prefix}")
endif()

# 3. build
run_step("building the consumer" "${CMAKE_COMMAND}" --build "${build}" ${config_args})

# 4. run the three executables (ffsr::ffsr, ffsr::urdf, ffsr::cvode)
foreach(exe consumer_dynamics consumer_urdf consumer_cvode)
  file(GLOB_RECURSE path "${build}/${exe}" "${build}/${exe}.exe" "${build}/*/${exe}" "${build}/*/${exe}.exe")
  if(NOT path)
    message(FATAL_ERROR "package consumer: ${exe} was not built")
  endif()
  list(GET path 0 path)
  run_step("running ${exe}" "${path}")
  if(NOT step_output MATCHES "M_ie at \\[0, 90, -90\\] deg = [0-9.]+ kg")
    message(FATAL_ERROR "package consumer: unexpected output of ${exe}:\n${step_output}")
  endif()
  message(STATUS "${exe}:\n${step_output}")
endforeach()

# 4b. the capture controller example (examples/capture_controller) against the installed package:
#     configure, build, run on the installed paper_7dof.urdf; it must reach the capture point
if(FFSR_SOURCE_DIR)
  set(example_args ${configure_args})
  list(REMOVE_AT example_args 0 1)  # -S <consumer source>
  run_step("configuring examples/capture_controller" "${CMAKE_COMMAND}" -S "${FFSR_SOURCE_DIR}/examples/capture_controller"
           ${example_args} -B "${WORK_DIR}/build_example")
  run_step("building examples/capture_controller" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build_example" ${config_args})
  file(GLOB_RECURSE path "${WORK_DIR}/build_example/capture_controller" "${WORK_DIR}/build_example/capture_controller.exe")
  if(NOT path)
    message(FATAL_ERROR "package consumer: examples/capture_controller was not built")
  endif()
  list(GET path 0 path)
  run_step("running examples/capture_controller" "${path}" "${prefix}/share/ffsr/robots/paper_7dof.urdf")
  if(NOT step_output MATCHES "capture point reached within [0-9.e+-]+ m")
    message(FATAL_ERROR "package consumer: unexpected output of examples/capture_controller:\n${step_output}")
  endif()
  message(STATUS "examples/capture_controller:\n${step_output}")
endif()

# 5. ffsr_add_scenario_test: the stored baseline passes, a moved value fails and is named
if(FFSR_SOURCE_DIR)
  set(ctest_args "${CMAKE_CTEST_COMMAND}" --output-on-failure -R "^consumer_scenario$")
  if(CONFIG)
    list(APPEND ctest_args -C "${CONFIG}")
  endif()
  execute_process(COMMAND ${ctest_args} WORKING_DIRECTORY "${build}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "1 tests passed|100% tests passed")
    message(FATAL_ERROR "package consumer: the scenario test against its stored baseline failed (${rc}):\n${out}\n${err}")
  endif()
  file(READ "${WORK_DIR}/baseline.json" baseline)
  string(JSON baseline SET "${baseline}" optimized integrated_effective_mass "1.5")
  file(WRITE "${WORK_DIR}/baseline.json" "${baseline}")
  execute_process(COMMAND ${ctest_args} WORKING_DIRECTORY "${build}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT out MATCHES "optimized\\.integrated_effective_mass: stored 1\\.5, now [0-9]")
    message(FATAL_ERROR "package consumer: the scenario test against a moved baseline did not fail naming "
                        "optimized.integrated_effective_mass (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "ffsr_add_scenario_test: passes on the stored baseline, fails on a moved value as expected")
endif()

# 6. without urdfdom and SUNDIALS: configure only
run_step("configuring the consumer without urdfdom and SUNDIALS" "${CMAKE_COMMAND}"
         ${configure_args} -B "${WORK_DIR}/build_dynamics_only" -DCONSUMER_DYNAMICS_ONLY=ON
         -DCMAKE_DISABLE_FIND_PACKAGE_urdfdom=ON -DCMAKE_DISABLE_FIND_PACKAGE_SUNDIALS=ON)
message(STATUS "find_package(ffsr) without urdfdom and SUNDIALS: ffsr::ffsr only, as expected")
