# A run stopped by a file it cannot write (a full disk, here the file size limit) names the step
# it stopped after: the last step taken, whose frame is the one that failed. A frame a step
# after the first is no "nothing was run" (exit code 2), and the fifth frame failing is no "step 3".
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/steps.toml "[cloth]
rows = 10
cols = 10
spacing = 0.1
mass = 1
[gravity]
[output]
fps = 100  # a frame every step
[integrator]
dt = 0.01
duration = 0.1
")
# Where each frame starts in positions.csv, from a run without a limit.
execute_process(COMMAND ${CLOTHLAB} run ${WORK}/steps.toml --no-html --out ${WORK}/whole
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the run without a limit failed (${code}):\n${out}${err}")
endif()
file(READ ${WORK}/whole/positions.csv positions)

foreach(failing 1 4)
  # Room for the frames before `failing` and a few bytes of it.
  string(FIND "${positions}" "\n${failing}," start)
  math(EXPR limit "${start} + 10")
  execute_process(COMMAND prlimit --fsize=${limit} -- ${CLOTHLAB} run ${WORK}/steps.toml --no-html
                          --out ${WORK}/out-${failing}
                  RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT code EQUAL 1)
    message(FATAL_ERROR "frame ${failing} failing: expected exit code 1, got ${code}\n${out}${err}")
  endif()
  if(NOT err MATCHES "positions\\.csv failed: File too large\n  the run stopped after step ${failing}; the frames before it are whole in ")
    message(FATAL_ERROR "frame ${failing} failing: expected 'the run stopped after step "
                        "${failing}' in:\n${err}")
  endif()
  file(STRINGS ${WORK}/out-${failing}/energy.csv rows)
  list(LENGTH rows count)
  math(EXPR expected "1 + ${failing}")
  if(NOT count EQUAL expected)
    message(FATAL_ERROR "frame ${failing} failing: energy.csv has ${count} lines, expected "
                        "${expected}")
  endif()
endforeach()
