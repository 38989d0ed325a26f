# `clothlab bench accuracy`: the work-precision study writes a CSV with one row per integrator
# and time step, in the documented columns, a plot script beside it, and the plot itself when
# matplotlib is there. (The orders and factors it shows are asserted in integrators.cpp; this
# checks the command's contract, never its timings.)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} bench accuracy --quick --min-seconds 0.001 --out out
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench accuracy failed with ${code}\n${out}${err}")
endif()
file(STRINGS ${WORK}/out/accuracy.csv lines)
list(GET lines 0 header)
set(expected "problem,integrator,dt,steps,error,wall_s_per_sim_s,force_evals_per_sim_s,stable")
if(NOT header STREQUAL expected)
  message(FATAL_ERROR "accuracy.csv header is\n  ${header}\nexpected\n  ${expected}")
endif()
list(LENGTH lines count)
if(NOT count EQUAL 43)  # 7 integrators x 6 time steps, and the header
  message(FATAL_ERROR "accuracy.csv has ${count} lines; expected 43\n${out}")
endif()
# RK4 at dt = 0.025 s: 160 steps, 4 force evaluations a step over 4 s = 160 per simulated second.
if(NOT out MATCHES "rk4 +0\\.025 +160 ")
  message(FATAL_ERROR "no RK4 row with dt = 0.025 s and 160 steps in the table:\n${out}")
endif()
if(NOT EXISTS ${WORK}/out/plot_accuracy.py)
  message(FATAL_ERROR "the plot script was not written next to the CSV")
endif()
if(EXISTS ${WORK}/out/work-precision.svg)
  file(READ ${WORK}/out/work-precision.svg svg)
  if(NOT svg MATCHES "<svg")
    message(FATAL_ERROR "work-precision.svg is not an SVG file")
  endif()
elseif(DEFINED ENV{CLOTHLAB_REQUIRE_PLOT})
  message(FATAL_ERROR "no plot was drawn, and CLOTHLAB_REQUIRE_PLOT is set:\n${err}")
elseif(NOT err MATCHES "python3-matplotlib")
  message(FATAL_ERROR "no plot was drawn and the warning does not say how to get one:\n${err}")
endif()

# A scene: RK4 reference, a shorter ladder; a missing scene is an error that says so.
execute_process(COMMAND ${CLOTHLAB} bench accuracy ${SCENE} --quick --time 0.4 --no-plot
                        --min-seconds 0.001 --integrators rk4,symplectic-euler --out scene
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench accuracy on ${SCENE} failed with ${code}\n${out}${err}")
endif()
file(STRINGS ${WORK}/scene/accuracy.csv lines)
list(LENGTH lines count)
if(NOT count EQUAL 7)  # 2 integrators x 3 time steps, and the header
  message(FATAL_ERROR "the scene's accuracy.csv has ${count} lines; expected 7\n${out}")
endif()
