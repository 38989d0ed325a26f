# A run the guard stops: exit code 3, an error naming step and particle, and complete frames.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/falls.toml "[[particle]]
position = [0, 0, 0]
mass = 1
[gravity]
[integrator]
dt = 0.01
duration = 10
[guard]
max_position = 1.0
")
execute_process(COMMAND ${CLOTHLAB} run ${WORK}/falls.toml --out ${WORK}/out
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 3)
  message(FATAL_ERROR "expected exit code 3, got ${code}\n${out}${err}")
endif()
if(NOT err MATCHES "simulation blew up at step [0-9]+ .*particle 0 position .* beyond the guard's bound of 1 m. Effects in play: gravity; integrator symplectic-euler")
  message(FATAL_ERROR "unexpected message:\n${err}")
endif()
file(STRINGS ${WORK}/out/energy.csv rows)
list(LENGTH rows count)
if(count LESS 2)
  message(FATAL_ERROR "no frames were kept")
endif()
foreach(row ${rows})
  if(row MATCHES "nan|inf")
    message(FATAL_ERROR "a frame holds a non-finite value: ${row}")
  endif()
endforeach()
