# check_grader.cmake: grades grader-selftest-cases and checks what the grader made of each case.
#
#   cmake -DCLOTHLAB=<clothlab> -DCASES=<grader-selftest-cases> -DWORK_DIR=<dir>
#         -P check_grader.cmake
cmake_minimum_required(VERSION 3.22)

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(results ${WORK_DIR}/results.json)
set(junit ${WORK_DIR}/junit.xml)

execute_process(
  COMMAND ${CMAKE_COMMAND} -E env NO_COLOR=1
          ${CLOTHLAB} grade --binary ${CASES} --timeout 2 --results ${results} --junit ${junit}
  RESULT_VARIABLE code
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
message("${out}${err}")

set(problems "")
function(problem text)
  set(problems "${problems}\n  ${text}" PARENT_SCOPE)
endfunction()

# Without --require-*, a grade with failures still exits 0.
if(NOT code EQUAL 0)
  problem("the grader exited with ${code}")
endif()
string(FIND "${out}" "Total: 5 / 18 points" at)
if(at EQUAL -1)
  problem("the table does not end with 'Total: 5 / 18 points'")
endif()
string(ASCII 27 escape)
string(FIND "${out}" "${escape}[" at)
if(NOT at EQUAL -1)
  problem("colour escapes were written although NO_COLOR is set")
endif()

# --- results.json -------------------------------------------------------------------------------
file(READ ${results} json)
string(JSON score GET "${json}" score)
string(JSON tests LENGTH "${json}" tests)
string(JSON seconds GET "${json}" execution_time)
if(NOT score EQUAL 5)
  problem("results.json: score ${score}, expected 5 (ex90.1, ex91.1 and ex91.2)")
endif()
if(NOT tests EQUAL 13)
  problem("results.json: ${tests} tests, expected 13")
endif()
# The hang is cut off at 2 s, so the whole run takes a few seconds.
if(seconds GREATER 10)
  problem("results.json: the run took ${seconds} s, so the hang was not cut off")
endif()
string(JSON number GET "${json}" tests 0 number)
if(NOT number STREQUAL "90.1")
  problem("results.json: the first test's number is ${number}, expected 90.1")
endif()

# Each case by name: its status, its score, and a piece of text its output must hold. The crash,
# abort and hang come before ex91.1, which still passes: each costs only its own case.
set(expected
  "ex90.1 passes|passed|2|passed"
  "ex90.2 fails with a hint|failed|0|hint: the answer is 2 & 1 < 2"
  "ex90.2 fails with a hint|failed|0|CHECK( answer == 2 ) failed"
  "ex90.2 fails with a hint|failed|0|values: 1 == 2"
  "ex90.2 fails with a hint|failed|0|printed by ex90.2 ??("
  "ex90.3 crashes with SIGSEGV|failed|0|crashed: SIGSEGV"
  "ex90.4 aborts|failed|0|crashed: SIGABRT"
  "ex90.5 hangs forever|failed|0|timed out after 2 s"
  "ex90.6 throws|failed|0|threw an exception: boom"
  "ex90.7 is not started|failed|0|not started"
  "ex90.8 exits without reporting|failed|0|exited with code 3 before reporting a result"
  "ex90.9 needs another exercise|failed|0|this test also needs ex90.7"
  "ex90.10 prints a pass and fails|failed|0|CHECK( 1 == 2 ) failed"
  "ex91.1 passes after the crashes|passed|2|passed"
  "ex91.2 names with * and ? still run|passed|1|passed"
  "ex92.1 is listed but never runs|failed|0|no test case ran")
math(EXPR last "${tests} - 1")
foreach(row IN LISTS expected)
  string(REPLACE "|" ";" row "${row}")
  list(GET row 0 name)
  list(GET row 1 want_status)
  list(GET row 2 want_score)
  list(GET row 3 want_text)
  set(found FALSE)
  foreach(i RANGE ${last})
    string(JSON test_name GET "${json}" tests ${i} name)
    if(NOT test_name STREQUAL name)
      continue()
    endif()
    set(found TRUE)
    string(JSON status GET "${json}" tests ${i} status)
    string(JSON test_score GET "${json}" tests ${i} score)
    string(JSON test_output GET "${json}" tests ${i} output)
    if(NOT status STREQUAL want_status)
      problem("${name}: status ${status}, expected ${want_status}")
    endif()
    if(NOT test_score EQUAL want_score)
      problem("${name}: score ${test_score}, expected ${want_score}")
    endif()
    string(FIND "${test_output}" "${want_text}" at)
    if(at EQUAL -1)
      problem("${name}: its output does not say '${want_text}':\n${test_output}")
    endif()
  endforeach()
  if(NOT found)
    problem("${name}: missing from results.json")
  endif()
endforeach()

# --- JUnit XML ------------------------------------------------------------------------------------
# One testsuite per exercise (12 here), one testcase per case, a failure per failed case (9), the
# hint's '&' and '<' escaped.
file(READ ${junit} xml)
function(count pattern out)
  string(REGEX MATCHALL "${pattern}" found "${xml}")
  list(LENGTH found n)
  set(${out} ${n} PARENT_SCOPE)
endfunction()
count("<testsuite " suites)
count("</testsuite>" suites_closed)
count("<testcase " cases)
count("</testcase>" cases_closed)
count("<failure " failures)
count("</failure>" failures_closed)
if(NOT suites EQUAL 13 OR NOT suites_closed EQUAL 13)
  problem("JUnit: ${suites} testsuites (${suites_closed} closed), expected 13")
endif()
if(NOT cases EQUAL 13 OR NOT cases_closed EQUAL 13)
  problem("JUnit: ${cases} testcases (${cases_closed} closed), expected 13")
endif()
if(NOT failures EQUAL 10 OR NOT failures_closed EQUAL 10)
  problem("JUnit: ${failures} failures (${failures_closed} closed), expected 10")
endif()
string(FIND "${xml}" "the answer is 2 &amp; 1 &lt; 2" at)
if(at EQUAL -1)
  problem("JUnit: the hint's '&' and '<' are not escaped")
endif()
string(REGEX MATCH "^<\\?xml [^\n]*\n<testsuites [^\n]*tests=\"13\" failures=\"10\"" head "${xml}")
if(NOT head)
  problem("JUnit: the root element does not count 13 tests and 10 failures")
endif()

if(problems)
  message(FATAL_ERROR "the grader got these wrong:${problems}")
endif()
