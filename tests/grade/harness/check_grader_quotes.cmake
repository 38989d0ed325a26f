# check_grader_quotes.cmake: the grader's output quoted in the README and the lessons still
# matches the grading tests, so that a quote cannot drift out of date unnoticed:
#   - "tests/grade/NN_x.cpp:LINE: CHECK( EXPR ) failed": that line of that file (give or take the
#     lines a check spans) holds a check of EXPR;
#   - "exNN.k NAME: failed" (or another status): a grading case has that name;
#   - "see lessons/NN-x/README.md, Exercise N.k": that lesson has that exercise's section.
#
#   cmake -DSOURCE=<project root> -P check_grader_quotes.cmake
cmake_minimum_required(VERSION 3.22)

if(NOT SOURCE)
  message(FATAL_ERROR "check_grader_quotes.cmake needs -DSOURCE=<project root>")
endif()

# A file's lines as a CMake list: ';', '[' and ']' (list syntax) become other characters first.
function(read_lines path out)
  file(READ ${path} text)
  string(REPLACE ";" "," text "${text}")
  string(REPLACE "[" "<" text "${text}")
  string(REPLACE "]" ">" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# What a check says with the punctuation and spelling that differ between source and output
# taken out: CHECK_NEAR_VEC(a, b, t) is reported as CHECK( ::grading::near((a), (b), (t)) ).
function(normalise text out)
  string(REPLACE "::grading::near" "" text "${text}")
  string(REPLACE "CHECK_NEAR_VEC" "" text "${text}")
  string(REGEX REPLACE "[ \t()<>]" "" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

file(GLOB grading_sources ${SOURCE}/tests/grade/[0-9][0-9]_*.cpp
     ${SOURCE}/tests/grade-hidden/[0-9][0-9]_*.cpp)
set(all_cases "")
foreach(source ${grading_sources})
  file(READ ${source} text)
  string(APPEND all_cases "${text}")
endforeach()

file(GLOB documents ${SOURCE}/README.md ${SOURCE}/lessons/[0-9][0-9]-*/README.md)
set(problems "")
set(checked 0)
foreach(document ${documents})
  file(RELATIVE_PATH shown ${SOURCE} ${document})
  read_lines(${document} lines)
  set(number 0)
  foreach(line IN LISTS lines)
    math(EXPR number "${number} + 1")
    # A failed check, quoted with its place.
    if(line MATCHES "(tests/grade(-hidden)?/[0-9][0-9]_[a-z_]+\\.cpp):([0-9]+): [A-Z_]+\\( (.*) \\) failed")
      set(file ${CMAKE_MATCH_1})
      set(at ${CMAKE_MATCH_3})
      normalise("${CMAKE_MATCH_4}" quoted)
      math(EXPR checked "${checked} + 1")
      if(NOT EXISTS ${SOURCE}/${file})
        string(APPEND problems "\n  ${shown}:${number}: quotes ${file}, which does not exist")
        continue()
      endif()
      read_lines(${SOURCE}/${file} source_lines)
      list(LENGTH source_lines count)
      # The check may span a few lines, and the compiler may name any of them.
      math(EXPR first "${at} - 4")
      math(EXPR last "${at} + 2")
      if(first LESS 0)
        set(first 0)
      endif()
      if(last GREATER_EQUAL count)
        math(EXPR last "${count} - 1")
      endif()
      set(window "")
      if(at LESS_EQUAL count)
        foreach(k RANGE ${first} ${last})
          list(GET source_lines ${k} source_line)
          string(APPEND window "${source_line}")
        endforeach()
      endif()
      normalise("${window}" window)
      string(FIND "${window}" "${quoted}" found)
      if(found EQUAL -1)
        string(APPEND problems "\n  ${shown}:${number}: quotes a failed check at ${file}:${at}, "
                               "but that line holds no such check; run the grader and quote "
                               "what it prints now")
      endif()
    endif()
    # A case, quoted with its status.
    if(line MATCHES "^ +(ex[0-9][0-9]\\.[0-9]+ [^:]+): (failed|crashed|timed out|not started|not compiled|exited)")
      set(name "${CMAKE_MATCH_1}")
      math(EXPR checked "${checked} + 1")
      string(FIND "${all_cases}" "TEST_CASE(\"${name}\"" found)
      if(found EQUAL -1)
        string(APPEND problems "\n  ${shown}:${number}: quotes the case \"${name}\", which no "
                               "grading test has")
      endif()
    endif()
    # Where to read.
    if(line MATCHES "see (lessons/[0-9][0-9]-[a-z-]+/README\\.md), Exercise ([0-9]+\\.[0-9]+)")
      set(lesson ${CMAKE_MATCH_1})
      set(exercise ${CMAKE_MATCH_2})
      math(EXPR checked "${checked} + 1")
      if(NOT EXISTS ${SOURCE}/${lesson})
        string(APPEND problems "\n  ${shown}:${number}: points to ${lesson}, which does not exist")
      else()
        file(STRINGS ${SOURCE}/${lesson} headings REGEX "^## Exercise ${exercise}[: ]")
        if(NOT headings)
          string(APPEND problems "\n  ${shown}:${number}: points to Exercise ${exercise} of "
                                 "${lesson}, which has no such section")
        endif()
      endif()
    endif()
  endforeach()
endforeach()

if(checked EQUAL 0)
  message(FATAL_ERROR "no quoted grader output found in the README or the lessons: is the "
                      "pattern out of date?")
endif()
if(problems)
  message(FATAL_ERROR "quoted grader output that no longer matches the grading tests:${problems}")
endif()
message(STATUS "${checked} quotes of the grader's output match the grading tests")
