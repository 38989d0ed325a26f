# `clothlab bench accuracy`: the work-precision study writes a CSV with one row per integrator
# and time step, in the documented columns, a plot script beside it, and the plot itself when
# matplotlib is there. (The orders and factors it shows are asserted in integrators.cpp; this
# checks the command's contract, never its timings.)
include(${CMAKE_CURRENT_LIST_DIR}/cli_bench_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
run_bench("bench accuracy" bench accuracy --quick --min-seconds 0.001 --out out)
check_header(${WORK}/out/accuracy.csv
             "problem,integrator,dt,steps,error,wall_s_per_sim_s,force_evals_per_sim_s,stable")
file(STRINGS ${WORK}/out/accuracy.csv lines)
list(LENGTH lines count)
if(NOT count EQUAL 43)  # 7 integrators x 6 time steps, and the header
  message(FATAL_ERROR "accuracy.csv has ${count} lines; expected 43\n${out}")
endif()
# RK4 at dt = 0.025 s: 160 steps, 4 force evaluations a step over 4 s = 160 per simulated second.
if(NOT out MATCHES "rk4 +0\\.025 +160 ")
  message(FATAL_ERROR "no RK4 row with dt = 0.025 s and 160 steps in the table:\n${out}")
endif()
check_plot(${WORK}/out/plot_accuracy.py ${WORK}/out/work-precision.svg "${err}")

# A scene: RK4 reference, a shorter ladder; a missing scene is an error that says so.
run_bench("bench accuracy on ${SCENE}" bench accuracy ${SCENE} --quick --time 0.4 --no-plot
          --min-seconds 0.001 --integrators rk4,symplectic-euler --out scene)
file(STRINGS ${WORK}/scene/accuracy.csv lines)
list(LENGTH lines count)
if(NOT count EQUAL 7)  # 2 integrators x 3 time steps, and the header
  message(FATAL_ERROR "the scene's accuracy.csv has ${count} lines; expected 7\n${out}")
endif()

# Without --time, the scene's default end time is one its ladder takes: lesson 02's spring
# (dt = 0.001 s, a longest step of 8 dt = 0.008 s) was refused with "--time 0.5 s is not a whole
# number of steps of 0.008 s", a --time the user never gave. A --time the user gives is still
# checked.
run_bench("bench accuracy on ${SCENE} without --time" bench accuracy ${SCENE} --quick --no-plot
          --min-seconds 0.001 --integrators symplectic-euler --out default-time)
if(NOT out MATCHES "symplectic-euler +0\\.008 +62 ")  # 62 steps of 0.008 s: 0.496 s, within 0.5 s
  message(FATAL_ERROR "no run of 62 steps of 0.008 s to 0.496 s:\n${out}")
endif()
execute_process(COMMAND ${CLOTHLAB} bench accuracy ${SCENE} --quick --no-plot --time 0.5
                        --min-seconds 0.001 --integrators symplectic-euler --out given-time
                WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT code EQUAL 1 OR NOT err MATCHES "--time 0\\.5 s is not a whole number of steps of 0\\.008 s")
  message(FATAL_ERROR "--time 0.5 on a scene of dt = 0.001 s: exit ${code}\n${err}")
endif()
