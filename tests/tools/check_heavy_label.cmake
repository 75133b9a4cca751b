# heavy_label_test: every name in tests/heavy_tests.cmake is a test of
# BUILD_DIR and carries the `heavy` label there. A renamed or removed test
# would otherwise leave a name that labels nothing, and the renamed test
# would silently run again in CI's sanitizer step.
# cmake -DBUILD_DIR=build -DLIST=tests/heavy_tests.cmake -P check_heavy_label.cmake
file(STRINGS "${LIST}" lines REGEX "^  \\[=\\[.*\\]=\\]$")
set(listed "")
foreach(line IN LISTS lines)
  string(REGEX REPLACE "^  \\[=\\[(.*)\\]=\\]$" "\\1" name "${line}")
  list(APPEND listed "${name}")
endforeach()
list(LENGTH listed n_listed)
if(n_listed EQUAL 0)
  message(FATAL_ERROR "${LIST}: no test names read")
endif()
execute_process(COMMAND ${CMAKE_CTEST_COMMAND} --test-dir "${BUILD_DIR}" -N -L heavy
                OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctest -N -L heavy failed (${rc}):\n${out}")
endif()
string(REGEX MATCHALL "Test +#[0-9]+: [^\n]*" rows "${out}")
set(labelled "")
foreach(row IN LISTS rows)
  string(REGEX REPLACE "^Test +#[0-9]+: " "" name "${row}")
  list(APPEND labelled "${name}")
endforeach()
set(missing "")
foreach(name IN LISTS listed)
  list(FIND labelled "${name}" at)
  if(at EQUAL -1)
    list(APPEND missing "${name}")
  endif()
endforeach()
if(missing)
  string(REPLACE ";" "\n  " shown "${missing}")
  message(FATAL_ERROR "tests/heavy_tests.cmake names tests that ${BUILD_DIR} does not have "
                      "(renamed or removed? update the list):\n  ${shown}")
endif()
message(STATUS "heavy label: all ${n_listed} listed tests found")
