# `clothlab bench boundary --particles`: a count out of range is refused with the range it takes
# (not "0.000000 to 1797...", a double's), and memory the system will not give is an error that
# says so, not an abort on an uncaught std::bad_alloc.

# expect_run(WHAT CODE EXPECTED ARGS...): `ARGS...` exits CODE with EXPECTED in its errors.
function(expect_run what code expected)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result STREQUAL code)
    message(FATAL_ERROR "${what}: expected exit code ${code}, got ${result}\n${out}${err}")
  endif()
  string(FIND "${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${what}: expected '${expected}' in the errors:\n${err}")
  endif()
endfunction()

foreach(count 0 4194305 9223372036854775807)
  expect_run("--particles ${count}" 105
             "--particles: Value ${count} not in range 1 to 4194304"
             ${CLOTHLAB} bench boundary --particles ${count} --steps 1 --repeats 1)
endforeach()
expect_run("--steps 0" 105 "--steps: Value 0 not in range 1 to 9223372036854775807"
           ${CLOTHLAB} bench boundary --steps 0)

# The most particles in 1 GB of address space: three worlds of 4 million do not fit.
if(NOT SANITIZE)  # the sanitizers reserve more address space than that at the start
  expect_run("--particles 4194304 in 1 GB" 1
             "error: bench boundary: not enough memory for the sizes asked for; expected fewer"
             sh -c "ulimit -v 1000000 && exec \"$0\" bench boundary --particles 4194304 \
--steps 1 --repeats 1" ${CLOTHLAB})
endif()
