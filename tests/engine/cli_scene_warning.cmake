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
