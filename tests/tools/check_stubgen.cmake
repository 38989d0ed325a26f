# check_stubgen.cmake: stubgen on small fixtures, its output compared with the expected one.
#
#   cmake -DSTUBGEN=<clothlab-stubgen> -DFIXTURES=<tests/tools/fixtures> -DWORK_DIR=<dir>
#         -P check_stubgen.cmake
cmake_minimum_required(VERSION 3.22)

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(problems "")

# A solved file comes back as the shipped stub, byte for byte.
execute_process(COMMAND ${STUBGEN} ${FIXTURES}/solved.cpp ${WORK_DIR}/solved.stub.cpp
                RESULT_VARIABLE code ERROR_VARIABLE err)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK_DIR}/solved.stub.cpp
                        ${FIXTURES}/solved.stub.cpp
                RESULT_VARIABLE differs)
if(NOT code EQUAL 0 OR NOT differs EQUAL 0)
  string(APPEND problems "\n  solved.cpp: exit ${code}, output differs from solved.stub.cpp ${err}")
endif()

# The stub of a stub is itself.
execute_process(COMMAND ${STUBGEN} ${FIXTURES}/solved.stub.cpp ${WORK_DIR}/again.cpp
                RESULT_VARIABLE code)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK_DIR}/again.cpp
                        ${FIXTURES}/solved.stub.cpp
                RESULT_VARIABLE differs)
if(NOT code EQUAL 0 OR NOT differs EQUAL 0)
  string(APPEND problems "\n  solved.stub.cpp: its stub is not itself")
endif()

# Broken markers: exit status 1, FILE:LINE: message, and no output file.
foreach(case "unbalanced.cpp:3: region ex01.1 has no END line"
             "mismatched.cpp:5: END ex01.2 closes region ex01.1"
             "nested.cpp:4: BEGIN ex01.2 inside region ex01.1"
             "malformed.cpp:3: malformed marker")
  string(REGEX MATCH "^[a-z]+\\.cpp" file "${case}")
  execute_process(COMMAND ${STUBGEN} ${FIXTURES}/${file} ${WORK_DIR}/${file}
                  RESULT_VARIABLE code ERROR_VARIABLE err)
  string(FIND "${err}" "${FIXTURES}/${case}" at)
  if(NOT code EQUAL 1 OR at EQUAL -1 OR EXISTS ${WORK_DIR}/${file})
    string(APPEND problems "\n  ${file}: exit ${code}, expected 1 and '${case}'; said: ${err}")
  endif()
endforeach()

if(problems)
  message(FATAL_ERROR "stubgen got these wrong:${problems}")
endif()
