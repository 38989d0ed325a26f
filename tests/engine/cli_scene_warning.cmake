# A scene with a warning still runs: `validate` exits 0, says "ok" on stdout and prints the
# warning, with FILE:LINE:COL, on stderr; `run` prints it before stepping and runs to the end.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(scene ${WORK}/fps.toml)
file(WRITE ${scene} "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n[gravity]\n"
                    "[integrator]\ndt = 0.01\nduration = 0.05\n[output]\nfps = 1000\n")
string(CONCAT expected "warning: ${scene}:9:7: fps = 1000 frames/s is more than the step rate "
                       "1/dt = 100 steps/s: a frame is written every step")

execute_process(COMMAND ${CLOTHLAB} validate ${scene}
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "validate: expected exit code 0, got ${code}\n${out}${err}")
endif()
if(NOT out MATCHES "fps.toml: ok: 1 particle")
  message(FATAL_ERROR "validate: no 'ok' on stdout:\n${out}")
endif()
string(FIND "${err}" "${expected}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "validate: the warning is not on stderr:\n${err}")
endif()

execute_process(COMMAND ${CLOTHLAB} run ${scene} --no-html --out ${WORK}/out
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "run: expected exit code 0, got ${code}\n${out}${err}")
endif()
string(FIND "${err}" "${expected}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "run: the warning is not on stderr:\n${err}")
endif()
# Every step wrote a frame: 5 steps and the start.
if(NOT out MATCHES "wrote 6 frames")
  message(FATAL_ERROR "run: expected a frame every step:\n${out}")
endif()

# A start past a 32-bit float's range, let through by a widened [guard]: `validate` warns of it
# at its place; `run` refuses it there, exit code 2, before it makes the folder, when the page
# would hold it; the CSV files alone (--no-html) keep doubles and take it.
set(scene ${WORK}/far.toml)
file(WRITE ${scene} "[guard]\nmax_position = 1e300\n[[particle]]\nposition = [0, 1e39, 0]\n"
                    "mass = 1\n[integrator]\ndt = 0.01\nduration = 0.05\n[output]\nfps = 100\n")
string(CONCAT expected "${scene}:4:12: [[particle]] #1 starts at (0, 1e+39, 0) m, beyond what a "
                       "32-bit float holds (3.40282e+38), which the page and positions.npy keep")
execute_process(COMMAND ${CLOTHLAB} validate ${scene}
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
string(FIND "${err}" "warning: ${expected}" at)
if(NOT code EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "validate far.toml: expected exit code 0 and the warning, got ${code}\n"
                      "${out}${err}")
endif()
execute_process(COMMAND ${CLOTHLAB} run ${scene} --out ${WORK}/far
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
string(FIND "${err}" "error: ${expected}" at)
if(NOT code EQUAL 2 OR at EQUAL -1 OR EXISTS ${WORK}/far)
  message(FATAL_ERROR "run far.toml: expected exit code 2, the error and no folder, got ${code}\n"
                      "${out}${err}")
endif()
string(FIND "${err}" "warning: ${expected}" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "run far.toml: the refusal is also printed as a warning:\n${err}")
endif()
execute_process(COMMAND ${CLOTHLAB} run ${scene} --no-html --out ${WORK}/far
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 0 OR NOT out MATCHES "wrote 6 frames")
  message(FATAL_ERROR "run far.toml --no-html: expected 6 frames, got ${code}\n${out}${err}")
endif()
