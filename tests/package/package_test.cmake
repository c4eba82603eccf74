# Included from tests/CMakeLists.txt. ctest case: install ffsr into a scratch prefix and build the
# consumer project tests/package against it (find_package(ffsr) with ffsr::ffsr, ffsr::urdf and
# ffsr::cvode); run the installed ffsr-optimize on share/ffsr/robots/paper_7dof_position.toml. It
# needs the project built first (cmake --build, then ctest).
add_test(NAME package_consumer
  COMMAND ${CMAKE_COMMAND}
    -DFFSR_BINARY_DIR=${PROJECT_BINARY_DIR}
    -DFFSR_SOURCE_DIR=${PROJECT_SOURCE_DIR}
    -DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_LIST_DIR}
    -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/package_consumer
    -DCONFIG=$<CONFIG>
    -DGENERATOR=${CMAKE_GENERATOR}
    -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
    -P ${CMAKE_CURRENT_LIST_DIR}/run_consumer.cmake)
# COST: the longest case of the suite (a configure, install and build of its own), started first so that
# ctest -j2 runs the other cases beside it instead of waiting for it at the end
set_tests_properties(package_consumer PROPERTIES LABELS package TIMEOUT 600 COST 10000)
