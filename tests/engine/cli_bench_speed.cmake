# `clothlab bench speed --quick --csv F`: the CSV has the documented header and every row's
# numbers are positive and finite; the reference and the naive baseline are both there. It never
# asserts a speed: that would fail on a busy machine.
cmake_policy(SET CMP0057 NEW)  # if(... IN_LIST ...)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} bench speed --quick --csv speed.csv
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench speed failed with ${code}\n${out}${err}")
endif()
file(STRINGS ${WORK}/speed.csv lines)
list(GET lines 0 header)
set(expected "variant,n,threads,springs,ns_per_spring_step,steps_per_s,particles")
if(NOT header STREQUAL expected)
  message(FATAL_ERROR "speed.csv header is\n  ${header}\nexpected\n  ${expected}")
endif()
list(REMOVE_AT lines 0)
set(variants "")
foreach(line ${lines})
  string(REPLACE "," ";" fields "${line}")
  list(LENGTH fields count)
  if(NOT count EQUAL 7)
    message(FATAL_ERROR "row '${line}' has ${count} fields; expected 7")
  endif()
  list(GET fields 0 variant)
  list(APPEND variants ${variant})
  foreach(index 1 2 3 4 5 6)
    list(GET fields ${index} value)
    # A positive finite number: digits, maybe a fraction and an exponent; no nan, inf or sign.
    if(NOT value MATCHES "^[0-9]+(\\.[0-9]+)?(e[-+][0-9]+)?$" OR value MATCHES "^0(\\.0+)?$")
      message(FATAL_ERROR "row '${line}': field ${index} is '${value}'; expected a positive "
                          "finite number")
    endif()
  endforeach()
endforeach()
foreach(variant reference readable naive kernel +aerodynamics +aerodynamics+ground implicit)
  if(NOT variant IN_LIST variants)
    message(FATAL_ERROR "no '${variant}' row in speed.csv:\n${out}")
  endif()
endforeach()
# The shipped stubs cannot run the scene: the student row is skipped, naming the exercise.
if(NOT out MATCHES "student: skipped: (ex[0-9][0-9]\\.[0-9] is not done|clothlab-student was not found)"
   AND NOT "student" IN_LIST variants)
  message(FATAL_ERROR "bench speed neither measured the student build nor said why not:\n${out}")
endif()
