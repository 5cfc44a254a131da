# Run after a GoogleTest executable is built (cmake -P): lists its tests and writes the CTest
# file that registers them one CTest test per test suite, up to GROUP_MAX tests each
# (`Suite.*`, `Suite.*#2`, ... for a larger suite), so that one process runs several tests.
# Tests matching a regular expression of SINGLE_FILE (one per line, # comments), and every test
# when GROUP_MAX is 1, are registered alone under their GoogleTest names. A process's start (the Vulkan
# loader, driver and validation layer, the sanitizer runtime) costs more than most tests
# (docs/building.md, "Build and test time").
#
# -D EXE=... CTEST_FILE=... WORKING_DIR=... SOURCE_DIR=... SINGLE_FILE=... GROUP_MAX=N
cmake_minimum_required(VERSION 3.25)  # the project's policies (CMP0012: if(TRUE))

execute_process(COMMAND "${EXE}" --gtest_list_tests
                WORKING_DIRECTORY "${WORKING_DIR}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE listing ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc}):\n${listing}\n${err}")
endif()

set(single_patterns "")
if(SINGLE_FILE AND EXISTS "${SINGLE_FILE}")
  file(STRINGS "${SINGLE_FILE}" lines)
  foreach(line IN LISTS lines)
    if(line AND NOT line MATCHES "^#")
      list(APPEND single_patterns "${line}")
    endif()
  endforeach()
endif()

# `Suite.` at column 0 opens a suite, `  Name` is one of its tests; `# GetParam() = ...`
# comments follow either. Other lines (gtest_main's banner) are not tests.
set(suites "")
string(REPLACE "\n" ";" listing_lines "${listing}")
foreach(line IN LISTS listing_lines)
  string(REGEX REPLACE " *#.*$" "" line "${line}")
  if(line MATCHES "^([^ ].*)\\.$")
    set(suite "${CMAKE_MATCH_1}")
    string(MAKE_C_IDENTIFIER "${suite}" key)
    list(APPEND suites "${suite}")
    set(tests_${key} "")
  elseif(line MATCHES "^  ([^ ]+)$" AND DEFINED suite)
    list(APPEND tests_${key} "${CMAKE_MATCH_1}")
  endif()
endforeach()

set(out "")
set(env "FOVEA_SOURCE_DIR=${SOURCE_DIR}")
macro(register name filter skip)
  string(APPEND out "add_test([==[${name}]==] [==[${EXE}]==] [==[--gtest_filter=${filter}]==])\n")
  string(APPEND out "set_tests_properties([==[${name}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKING_DIR}]==] "
                    "ENVIRONMENT [==[${env}]==]")
  if(${skip})  # a group passes when its tests pass or skip; a test alone can be reported skipped
    string(APPEND out " SKIP_REGULAR_EXPRESSION [==[\\[  SKIPPED \\]]==]")
  endif()
  string(APPEND out ")\n")
endmacro()

foreach(suite IN LISTS suites)
  string(MAKE_C_IDENTIFIER "${suite}" key)
  set(part 1)
  set(grouped "")
  foreach(test IN LISTS tests_${key})
    set(full "${suite}.${test}")
    set(alone FALSE)
    if(GROUP_MAX EQUAL 1)
      set(alone TRUE)
    endif()
    foreach(p IN LISTS single_patterns)
      if(full MATCHES "${p}")
        set(alone TRUE)
      endif()
    endforeach()
    if(alone)
      register("${full}" "${full}" TRUE)
    else()
      list(APPEND grouped "${full}")
    endif()
  endforeach()
  list(LENGTH grouped n)
  if(n EQUAL 1)
    register("${grouped}" "${grouped}" TRUE)
  elseif(n GREATER 1)
    set(i 0)
    while(i LESS n)
      list(SUBLIST grouped ${i} ${GROUP_MAX} chunk)
      list(JOIN chunk ":" filter)
      if(n LESS_EQUAL GROUP_MAX)
        set(name "${suite}.*")
      else()
        set(name "${suite}.*#${part}")
      endif()
      register("${name}" "${filter}" FALSE)
      math(EXPR i "${i} + ${GROUP_MAX}")
      math(EXPR part "${part} + 1")
    endwhile()
  endif()
endforeach()

file(WRITE "${CTEST_FILE}.tmp" "${out}")
file(RENAME "${CTEST_FILE}.tmp" "${CTEST_FILE}")
