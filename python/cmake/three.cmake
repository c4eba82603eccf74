# three.js for the 3-D view (ffsr.view), fetched at configure time from the npm registry with npm
# (`npm pack three@VERSION`), checked against the sha256 pinned in python/three.sha256, and installed
# into the package as ffsr/view_assets/three/ (the page inlines it: it opens offline). The repository
# holds none of its files. -DFFSR_THREE_TARBALL=FILE uses a tarball already downloaded (same check).
# Any failure (no npm, no network, another checksum) stops the configure with a message saying so.

file(STRINGS ${CMAKE_CURRENT_SOURCE_DIR}/three.sha256 ffsr_three_pin REGEX "^[0-9a-f]+  three-.*\\.tgz$")
list(LENGTH ffsr_three_pin ffsr_three_lines)
if(NOT ffsr_three_lines EQUAL 1)
  message(FATAL_ERROR "python/three.sha256: expected one line '<sha256>  three-<version>.tgz'")
endif()
string(REGEX REPLACE "^([0-9a-f]+)  (three-(.*)\\.tgz)$" "\\1;\\2;\\3" ffsr_three_pin "${ffsr_three_pin}")
list(GET ffsr_three_pin 0 FFSR_THREE_SHA256)
list(GET ffsr_three_pin 1 ffsr_three_file)
list(GET ffsr_three_pin 2 FFSR_THREE_VERSION)

set(FFSR_THREE_TARBALL "" CACHE FILEPATH "npm's tarball of three (${ffsr_three_file}), not downloaded")
set(ffsr_three_dir ${CMAKE_CURRENT_BINARY_DIR}/three-npm)
set(ffsr_three_tgz ${ffsr_three_dir}/${ffsr_three_file})

function(ffsr_three_sha256_ok file out)
  set(ok FALSE)
  if(EXISTS ${file})
    file(SHA256 ${file} sum)
    if(sum STREQUAL FFSR_THREE_SHA256)
      set(ok TRUE)
    endif()
  endif()
  set(${out} ${ok} PARENT_SCOPE)
endfunction()

ffsr_three_sha256_ok(${ffsr_three_tgz} ffsr_three_have)
if(NOT ffsr_three_have)
  file(REMOVE_RECURSE ${ffsr_three_dir})
  file(MAKE_DIRECTORY ${ffsr_three_dir})
  if(FFSR_THREE_TARBALL)
    file(COPY_FILE ${FFSR_THREE_TARBALL} ${ffsr_three_tgz})
    set(ffsr_three_from "FFSR_THREE_TARBALL=${FFSR_THREE_TARBALL}")
  else()
    find_program(FFSR_NPM npm)
    if(NOT FFSR_NPM)
      message(FATAL_ERROR "ffsr: the package build fetches three.js ${FFSR_THREE_VERSION} (the 3-D view's) "
                          "with npm, which is not installed (Debian: apt-get install npm; or "
                          "-DFFSR_THREE_TARBALL=FILE)")
    endif()
    message(STATUS "ffsr: npm pack three@${FFSR_THREE_VERSION}")
    execute_process(COMMAND ${FFSR_NPM} pack three@${FFSR_THREE_VERSION} --pack-destination ${ffsr_three_dir}
                            --silent
                    WORKING_DIRECTORY ${ffsr_three_dir}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT EXISTS ${ffsr_three_tgz})
      message(FATAL_ERROR "ffsr: npm pack three@${FFSR_THREE_VERSION} failed (exit ${rc}), so the 3-D view's "
                          "three.js is missing:\n${err}${out}")
    endif()
    set(ffsr_three_from "npm pack three@${FFSR_THREE_VERSION}")
  endif()
  ffsr_three_sha256_ok(${ffsr_three_tgz} ffsr_three_have)
  if(NOT ffsr_three_have)
    file(SHA256 ${ffsr_three_tgz} got)
    file(REMOVE_RECURSE ${ffsr_three_dir})
    message(FATAL_ERROR "ffsr: ${ffsr_three_file} from ${ffsr_three_from} has sha256 ${got}, but "
                        "python/three.sha256 pins ${FFSR_THREE_SHA256}: not the pinned three.js")
  endif()
endif()

set(ffsr_three_members package/build/three.module.min.js package/examples/jsm/controls/OrbitControls.js
                       package/LICENSE)
file(REMOVE_RECURSE ${ffsr_three_dir}/package)
file(ARCHIVE_EXTRACT INPUT ${ffsr_three_tgz} DESTINATION ${ffsr_three_dir} PATTERNS ${ffsr_three_members})
foreach(m IN LISTS ffsr_three_members)
  if(NOT EXISTS ${ffsr_three_dir}/${m})
    message(FATAL_ERROR "ffsr: ${ffsr_three_file} has no ${m}")
  endif()
  list(APPEND ffsr_three_files ${ffsr_three_dir}/${m})
endforeach()
install(FILES ${ffsr_three_files} DESTINATION ffsr/view_assets/three COMPONENT python)
message(STATUS "ffsr: three.js ${FFSR_THREE_VERSION} (sha256 checked) goes into ffsr/view_assets/three")
