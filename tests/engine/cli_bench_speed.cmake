# `clothlab bench speed --quick --csv F`: the CSV has the documented header and every row's
# numbers are positive and finite; every variant is there, and the bare and plain loops agree
# with the reference bit for bit. It never asserts a speed: that would fail on a busy machine.
cmake_policy(SET CMP0057 NEW)  # if(... IN_LIST ...)
cmake_policy(SET CMP0007 NEW)  # a list keeps its empty elements (bare's ratio below)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} bench speed --quick --csv speed.csv
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench speed failed with ${code}\n${out}${err}")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/bench_csv.cmake)
bench_csv_rows(${WORK}/speed.csv
               "variant,n,threads,springs,ns_per_spring_step,steps_per_s,particles" 1 lines)
set(variants "")
foreach(line ${lines})
  string(REPLACE "," ";" fields "${line}")
  list(GET fields 0 variant)
  list(APPEND variants ${variant})
endforeach()
foreach(variant reference float readable naive bare plain kernel +aerodynamics +aerodynamics+ground
        float+aerodynamics implicit)
  if(NOT variant IN_LIST variants)
    message(FATAL_ERROR "no '${variant}' row in speed.csv:\n${out}")
  endif()
endforeach()
# The bare loop (the engine's kernels on a state kept in the fast layout, no copies, no guard)
# and the plain loops (a list of springs, arrays of x, y and z, a loop a stage) compute the
# reference's physics bit for bit, at both sizes; bare on 1 thread and on every core, plain on
# one, set against the reference's step of the same run.
# (A row's "; " would cut it in two as a CMake list: a comma stands for it.)
string(REPLACE ";" "," out_commas "${out}")
foreach(loop "bare;" "plain;reference / plain [0-9.]+, ")
  list(GET loop 0 name)
  list(GET loop 1 ratio)
  string(REGEX MATCHALL "  ${name} +[0-9]+ +[^\n]*" rows "${out_commas}")
  string(REGEX MATCHALL "  ${name} +1 +" rows_1 "${out_commas}")
  list(LENGTH rows_1 count_1)
  if(NOT count_1 EQUAL 2)
    message(FATAL_ERROR "expected a 1-thread ${name} row per size, found ${count_1}:\n${out}")
  endif()
  foreach(row ${rows})
    if(NOT row MATCHES "${ratio}the same bits as reference after 20 steps")
      message(FATAL_ERROR "the ${name} loop does not compute the reference's physics:\n  ${row}")
    endif()
  endforeach()
endforeach()
# Each float row is set against its double twin of the same run and says how far single
# precision took the cloth from the double run: a small drift, not another physics.
foreach(pair "float;reference" "float\\+aerodynamics;\\+aerodynamics")
  list(GET pair 0 single)
  list(GET pair 1 twin)
  string(REGEX MATCHALL "  ${single} +[0-9]+ +[^\n]*" float_rows "${out_commas}")
  list(LENGTH float_rows float_count)
  if(float_count LESS 2)
    message(FATAL_ERROR "expected a '${single}' row per size, found ${float_count}:\n${out}")
  endif()
  foreach(row ${float_rows})
    if(NOT row MATCHES "${single} / ${twin} [0-9.]+, ([0-9.]+)e-0*([0-9]+) m from the double run")
      message(FATAL_ERROR "a float row without its ratio or its drift:\n  ${row}")
    endif()
    if(CMAKE_MATCH_2 LESS 5)  # the drift after 20 steps: 1e-5 m or more is not rounding
      message(FATAL_ERROR "the float run drifted too far from the double run:\n  ${row}")
    endif()
  endforeach()
endforeach()
# With several repeats, each ratio of the run is taken turn by turn (the two rows' times of one
# repeat, measured one soon after the other) and printed as the median of those ratios with
# their range: float over reference, reference over plain, and 1 thread over 2 (the speed-up).
execute_process(COMMAND ${CLOTHLAB} bench speed --sizes 16 --variants reference,float,plain
                        --threads 2 --repeats 3 --min-seconds 0.01 --no-student
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE turns ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench speed --repeats 3 failed with ${code}\n${turns}${err}")
endif()
set(number "([0-9]+\\.[0-9]+)")
foreach(pattern "float +1 [^\n]*float / reference ${number} \\(${number} to ${number} in 3 turns\\); "
                "plain +1 [^\n]*reference / plain ${number} \\(${number} to ${number} in 3 turns\\); "
                "reference +2 [^\n]*speed-up over 1 thread ${number} \\(${number} to ${number} in 3 turns\\)")
  if(NOT turns MATCHES "${pattern}")
    message(FATAL_ERROR "no ratio taken turn by turn, with its range, matching\n  ${pattern}\nin:\n${turns}")
  endif()
  # The median of three ratios lies within their range.
  if(CMAKE_MATCH_2 GREATER CMAKE_MATCH_1 OR CMAKE_MATCH_1 GREATER CMAKE_MATCH_3)
    message(FATAL_ERROR "a median outside its range: ${CMAKE_MATCH_0}")
  endif()
endforeach()
# The shipped stubs cannot run the scene: the student row is skipped, naming the exercise.
if(NOT out MATCHES "student: skipped: (ex[0-9][0-9]\\.[0-9] is not done|clothlab-student was not found)"
   AND NOT "student" IN_LIST variants)
  message(FATAL_ERROR "bench speed neither measured the student build nor said why not:\n${out}")
endif()
