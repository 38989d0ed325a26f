# check_submissions.cmake: `clothlab grade --submission DIR` on planted submissions, each graded
# in the same scratch folder the way an instructor grades a class in turn:
#   partial  ex01 and ex02 solved, the rest missing: exactly the points of ex01 and ex02
#   crash    ex01 with a kernel that aborts on one case's input: ex01 loses that case only
#   hang     ex01 with a kernel that never returns on one case's input: cut off at the timeout
#   broken   ex01 solved, ex02 with a typo, ex03 calling what it never defines: ex02 and ex03
#            reported as not compiling, with the compiler's and the linker's errors, ex01 graded;
#            the same grade, case by case, as the student's own grading
# and checks that the user's exercises/ is never touched.
#
#   cmake -DCLOTHLAB=<clothlab> -DSOURCE=<project source> -DWORK_DIR=<dir>
#         -P check_submissions.cmake
cmake_minimum_required(VERSION 3.22)

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(problems "")
macro(problem text)
  string(APPEND problems "\n  ${text}")
endmacro()

# The points of every case, from the table (hidden cases included).
execute_process(COMMAND ${CLOTHLAB} grade --impl stubs --hidden --list OUTPUT_VARIABLE table
                RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "clothlab grade --list failed:\n${table}")
endif()
# points_of(VAR REGEX): the points of the cases whose line matches REGEX.
function(points_of var regex)
  string(REPLACE "\n" ";" lines "${table}")
  set(sum 0)
  foreach(line ${lines})
    if(line MATCHES "^ex[0-9]" AND line MATCHES "${regex}" AND line MATCHES " ([0-9]+)  [a-z_]+$")
      math(EXPR sum "${sum} + ${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${var} ${sum} PARENT_SCOPE)
endfunction()
points_of(ex01 "^ex01\\.")
points_of(ex02 "^ex02\\.")
points_of(crashed "^ex01\\.1 +ex01\\.1 gravity on a 2 kg particle is m g ")
points_of(hung "^ex01\\.2 +ex01\\.2 the pull falls with the square of the distance ")
if(crashed EQUAL 0 OR hung EQUAL 0 OR ex01 EQUAL 0)
  message(FATAL_ERROR "the cases this test plants faults in are not in the table:\n${table}")
endif()

# The names and SHA-256 sums of the user's exercise files, to check they are never touched.
function(exercise_sums var)
  file(GLOB files ${SOURCE}/exercises/*)
  set(sums "")
  foreach(f ${files})
    file(SHA256 ${f} sum)
    list(APPEND sums "${f}=${sum}")
  endforeach()
  set(${var} "${sums}" PARENT_SCOPE)
endfunction()
exercise_sums(sums_before)

# grade_submission(NAME EXPECTED_SCORE ARGS...): grades WORK_DIR/NAME, checks results.json's
# score, and leaves the output in out_NAME and the results in json_NAME.
function(grade_submission name expected)
  set(results ${WORK_DIR}/${name}.json)
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env NO_COLOR=1 ${CLOTHLAB} grade --submission ${WORK_DIR}/${name}
            --scratch ${WORK_DIR}/scratch --results ${results} --hidden ${ARGN}
    RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("--- ${name}: exit ${code}\n${out}${err}")
  set(out_${name} "${out}" PARENT_SCOPE)
  if(NOT code EQUAL 0)
    set(problems "${problems}\n  ${name}: the grader exited with ${code}" PARENT_SCOPE)
    return()
  endif()
  file(READ ${results} json)
  set(json_${name} "${json}" PARENT_SCOPE)
  string(JSON score GET "${json}" score)
  if(NOT score EQUAL expected)
    set(problems "${problems}\n  ${name}: score ${score}, expected ${expected}" PARENT_SCOPE)
  endif()
endfunction()

# The status of the case called NAME in results.json text JSON.
function(case_status var json case_name)
  string(JSON count LENGTH "${json}" tests)
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    string(JSON name GET "${json}" tests ${i} name)
    if(name STREQUAL case_name)
      string(JSON status GET "${json}" tests ${i} status)
      string(JSON output GET "${json}" tests ${i} output)
      string(JSON visibility GET "${json}" tests ${i} visibility)
      set(${var} "${status}|${visibility}|${output}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${var} "missing" PARENT_SCOPE)
endfunction()

# --- partial ------------------------------------------------------------------------------------
file(MAKE_DIRECTORY ${WORK_DIR}/partial/exercises)
file(COPY ${SOURCE}/solutions/01_particles_and_euler.cpp DESTINATION ${WORK_DIR}/partial)
file(COPY ${SOURCE}/solutions/02_spring_dampers.cpp DESTINATION ${WORK_DIR}/partial/exercises)
file(WRITE ${WORK_DIR}/partial/notes.cpp "// not an exercise file\n")
math(EXPR expected "${ex01} + ${ex02}")
grade_submission(partial ${expected} --autolab)
string(REGEX MATCH "[^\n]*\n?$" last_line "${out_partial}")
string(STRIP "${last_line}" last_line)
string(JSON autolab_01 ERROR_VARIABLE bad GET "${last_line}" scores "ex01.3")
string(JSON autolab_07 ERROR_VARIABLE bad07 GET "${last_line}" scores "ex07.2")
string(JSON board ERROR_VARIABLE bad_board GET "${last_line}" scoreboard 0)
points_of(ex01_3 "^ex01\\.3 ")
if(bad OR bad07 OR bad_board OR NOT autolab_01 EQUAL ex01_3 OR NOT autolab_07 EQUAL 0
   OR NOT board EQUAL expected)
  problem("partial: the last line is not Autolab's summary with ex01.3 = ${ex01_3}, "
          "ex07.2 = 0 and a total of ${expected}: \"${last_line}\"")
endif()
foreach(text "Graded from the submission: 01_particles_and_euler.cpp, 02_spring_dampers.cpp"
        "Not in the submission (graded on the shipped stub): 03_aerodynamics.cpp"
        "Ignored (not an exercise file): notes.cpp")
  string(FIND "${out_partial}" "${text}" at)
  if(at EQUAL -1)
    problem("partial: the output does not say \"${text}\"")
  endif()
endforeach()
if(EXISTS ${SOURCE}/tests/grade-hidden/02_spring_dampers.cpp)
  case_status(hidden "${json_partial}"
              "ex02.1 hidden: moving and turning the whole spring turns its force with it")
  if(NOT hidden MATCHES "^passed\\|after_due_date\\|")
    problem("partial: the hidden ex02.1 case is not passed with visibility after_due_date: "
            "${hidden}")
  endif()
  case_status(hidden "${json_partial}" "ex02.1 hidden: the spring and the damper add")
  if(NOT hidden MATCHES "^passed\\|hidden\\|")
    problem("partial: the case marked POINTS_VISIBILITY(1, hidden) is not hidden: ${hidden}")
  endif()
endif()

# --- crash: abort() on the input of one case -------------------------------------------------------
file(READ ${SOURCE}/solutions/01_particles_and_euler.cpp text)
string(REPLACE "// BEGIN ex01.1: see lessons/01-particles-and-euler/README.md"
       "// BEGIN ex01.1: see lessons/01-particles-and-euler/README.md\n  if (m == 2.0) std::abort();"
       crash "#include <cstdlib>\n${text}")
string(REPLACE "// BEGIN ex01.2: see lessons/01-particles-and-euler/README.md"
       "// BEGIN ex01.2: see lessons/01-particles-and-euler/README.md\n  volatile long spin = 0;\n  while (m1 == 3.0) spin = spin + 1;"
       hang "${text}")
if(crash STREQUAL text OR hang STREQUAL text)
  message(FATAL_ERROR "the markers this test plants faults at are not in solutions/01")
endif()
file(WRITE ${WORK_DIR}/crash/01_particles_and_euler.cpp "${crash}")
math(EXPR expected "${ex01} - ${crashed}")
grade_submission(crash ${expected} --exercise ex01)
case_status(status "${json_crash}" "ex01.1 gravity on a 2 kg particle is m g")
if(NOT status MATCHES "^failed\\|visible\\|crashed: SIGABRT")
  problem("crash: the aborting case is not reported as crashed with SIGABRT: ${status}")
endif()

# --- hang: an endless loop on the input of one case ------------------------------------------------
file(WRITE ${WORK_DIR}/hang/01_particles_and_euler.cpp "${hang}")
math(EXPR expected "${ex01} - ${hung}")
string(TIMESTAMP start "%s")
grade_submission(hang ${expected} --exercise ex01 --timeout 3)
string(TIMESTAMP end "%s")
math(EXPR took "${end} - ${start}")
case_status(status "${json_hang}" "ex01.2 the pull falls with the square of the distance")
if(NOT status MATCHES "^failed\\|visible\\|timed out after 3 s")
  problem("hang: the looping case is not reported as timed out after 3 s: ${status}")
endif()
if(took GREATER 120)
  problem("hang: grading took ${took} s, so the loop was not cut off at 3 s")
endif()

# --- broken: ex01 solved, ex02 with a typo, ex03 that does not link ------------------------------
# A file that does not compile or link costs its own exercises only: they are reported as not
# compiled, with the compiler's or the linker's error, and ex01 is graded as solved. The student's
# own grading of the same files (--exercises, as `clothlab grade` grades exercises/) gives every
# case the same result.
file(READ ${SOURCE}/solutions/02_spring_dampers.cpp text)
string(REGEX REPLACE "return ([^;]*);" "retrun \\1;" broken "${text}")
file(WRITE ${WORK_DIR}/broken/02_spring_dampers.cpp "${broken}")
file(COPY ${SOURCE}/solutions/01_particles_and_euler.cpp DESTINATION ${WORK_DIR}/broken)
# And ex03 compiles but does not link: it calls a function it never defines.
file(READ ${SOURCE}/solutions/03_aerodynamics.cpp text)
file(WRITE ${WORK_DIR}/broken/03_aerodynamics.cpp "${text}
namespace clothlab {
double helper_never_defined();
double uses_helper() { return helper_never_defined(); }
}  // namespace clothlab
")
grade_submission(broken ${ex01})
foreach(text "exercises/02_spring_dampers.cpp does not compile:"
        "exercises/02_spring_dampers.cpp:" "error:")
  string(FIND "${out_broken}" "${text}" at)
  if(at EQUAL -1)
    problem("broken: the output does not say \"${text}\"")
  endif()
endforeach()
case_status(status "${json_broken}" "ex01.1 gravity on a 2 kg particle is m g")
if(NOT status MATCHES "^passed\\|visible\\|")
  problem("broken: ex01.1, whose file compiles, is not passed beside the broken ex02: ${status}")
endif()
case_status(status "${json_broken}"
            "ex02.1 a stretched spring pulls and a compressed one pushes")
if(NOT status MATCHES "^failed\\|visible\\|not compiled\nexercises/02_spring_dampers.cpp does not compile:\n.*error:")
  problem("broken: an ex02 case is not reported as not compiled with the error: ${status}")
endif()
case_status(status "${json_broken}" "ex03.1 air hitting a right triangle head on pushes with 30 N")
if(NOT status MATCHES "^failed\\|visible\\|not compiled\nexercises/03_aerodynamics.cpp does not compile:\n.*undefined reference")
  problem("broken: an ex03 case is not reported as not linking, with the linker's error: ${status}")
endif()
# What every student sees at once (results.json's top-level output) counts the visible cases
# alone: ex02.1's row has the points of its visible cases, and no hidden case is named.
points_of(ex02_1_visible "^ex02\\.1 .*  visible$")
string(JSON top GET "${json_broken}" output)
if(NOT top MATCHES "\nex02\\.1 +0 / ${ex02_1_visible} " OR top MATCHES "hidden:")
  problem("broken: the top-level output counts or names hidden cases:\n${top}")
endif()
# The same files graded as the student's own.
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env NO_COLOR=1 ${CLOTHLAB} grade --exercises ${WORK_DIR}/broken
          --scratch ${WORK_DIR}/own-scratch --results ${WORK_DIR}/broken-own.json --hidden
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("--- broken, graded as the student's own: exit ${code}\n${out}${err}")
file(READ ${WORK_DIR}/broken-own.json json_own)
string(JSON count_own LENGTH "${json_own}" tests)
string(JSON count LENGTH "${json_broken}" tests)
if(NOT code EQUAL 0 OR NOT count EQUAL count_own)
  problem("broken: graded as the student's own, exit ${code} and ${count_own} cases, where "
          "--submission graded ${count}")
else()
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    foreach(key name status score max_score visibility output)
      string(JSON submitted GET "${json_broken}" tests ${i} ${key})
      string(JSON own GET "${json_own}" tests ${i} ${key})
      if(NOT submitted STREQUAL own)
        string(JSON name GET "${json_broken}" tests ${i} name)
        problem("broken: \"${name}\" has ${key} \"${submitted}\" with --submission but \"${own}\" "
                "as the student's own")
      endif()
    endforeach()
  endforeach()
endif()

# --- the user's tree ---------------------------------------------------------------------------
exercise_sums(sums_after)
if(NOT sums_before STREQUAL sums_after)
  problem("the user's exercises/ changed while grading submissions")
endif()

if(problems)
  message(FATAL_ERROR "grading submissions went wrong:${problems}")
endif()
message("partial, crash, hang and broken submissions graded as expected")
