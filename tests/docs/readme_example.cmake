# The README's library example, compiled and run from the README's own text, so that it cannot rot.
#
# At configure time the ```cpp block under "## The library" of README.md is cut into its #include
# lines and its statements, which are wrapped into main(); the program prints M_ie and F, and the
# ctest case readme_example compares them with the values the README's comments give
# ("// 5.8158 kg", "// Eq. 24: 1840 N"), to the digits the README shows. Editing the README
# reconfigures the build.
set(_readme ${PROJECT_SOURCE_DIR}/README.md)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_readme})
file(READ ${_readme} _text)
string(REGEX MATCH "\n## The library\n[^`]*```cpp\n([^`]*)```" _block "${_text}")
if(NOT CMAKE_MATCH_1)
  message(FATAL_ERROR "README.md: no ```cpp block under '## The library' (the readme_example test compiles it)")
endif()
set(_code "${CMAKE_MATCH_1}")
string(REGEX REPLACE "(^|\n)[^#\n][^\n]*" "" _includes "${_code}")  # the lines that start with #
string(REGEX REPLACE "#include [^\n]*\n" "" _body "${_code}")
string(REGEX MATCH "// ([0-9.]+) kg" _m "${_code}")
set(_expect_mass "${CMAKE_MATCH_1}")
string(REGEX MATCH "Eq\\. 24: ([0-9.]+) N" _f "${_code}")
set(_expect_force "${CMAKE_MATCH_1}")
if(NOT _expect_mass OR NOT _expect_force)
  message(FATAL_ERROR "README.md: the library example's comments must give M_ie ('// X kg') and F ('Eq. 24: X N')")
endif()
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp.in
"// Generated from README.md (tests/docs/readme_example.cmake): do not edit.
${_includes}
#include <cstdio>

int main() {
${_body}
  std::printf(\"%.17g %.17g\\n\", M_ie, F);
  return 0;
}
")
configure_file(${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp.in ${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp COPYONLY)
add_executable(readme_example ${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp)
target_link_libraries(readme_example PRIVATE ffsr::urdf)
target_compile_options(readme_example PRIVATE ${FFSR_WARNINGS})
add_test(NAME readme_example
         COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:readme_example> -DMASS=${_expect_mass}
                 -DFORCE=${_expect_force} -P ${CMAKE_CURRENT_SOURCE_DIR}/docs/readme_example_check.cmake
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(readme_example PROPERTIES LABELS docs TIMEOUT 60)
