# `clothlab bench methods --quick`: lesson 12's bake-off on its three scenes writes one CSV row per
# scene and setting in the documented columns; in each scene the reference's difference from
# itself at half its step is below every stable method's error (the reference has converged), and
# symplectic Euler's error falls as its step falls; the plot script is written, and the plot drawn
# when matplotlib is there. Its timings are never checked. Then `--speed` on a small grid writes
# its CSV, with VBD's rows, readable and engine room (numbers, of either sign), and prints the
# measured bound on an XPBD iteration and on two threads.
cmake_policy(VERSION 3.22)  # quoted strings are strings, never variables' names (CMP0054)
include(${CMAKE_CURRENT_LIST_DIR}/cli_bench_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
run_bench("bench methods" bench methods --quick --min-seconds 0.001 --out out)
# Per scene, in --quick: the reference, symplectic Euler x 3 steps, RK4 x 2, implicit Euler x 3,
# XPBD x 5 settings, VBD x 2, and the local/global solver x 2 when the engine has it.
read_methods_csv(${WORK}/out/methods.csv 16 18)
foreach(scene bakeoff-hanging-sheet bakeoff-gusty-flag bakeoff-drape)
  set(rows 0)
  set(self_difference "")
  set(errors "")  # the stable methods' errors
  set(euler "")   # symplectic Euler's errors, coarsest step first
  foreach(line IN LISTS lines)
    string(REPLACE "," ";" f "${line}")
    list(GET f 0 name)
    if(NOT name STREQUAL scene)
      continue()
    endif()
    math(EXPR rows "${rows} + 1")
    list(GET f 1 method)
    list(GET f 6 error)
    list(GET f 10 stable)
    if(method STREQUAL "reference")
      set(self_difference ${error})
    elseif(stable STREQUAL "true")
      list(APPEND errors ${error})
      if(method STREQUAL "symplectic-euler")
        list(APPEND euler ${error})
      endif()
    endif()
  endforeach()
  if(NOT rows EQUAL rows_per_scene)
    message(FATAL_ERROR "${scene}: ${rows} rows in methods.csv; expected ${rows_per_scene}\n${out}")
  endif()
  if(self_difference STREQUAL "" OR errors STREQUAL "")
    message(FATAL_ERROR "${scene}: no reference row or no stable run\n${out}")
  endif()
  foreach(error IN LISTS errors)
    if(NOT self_difference LESS error)
      message(FATAL_ERROR "${scene}: the reference differs from itself by ${self_difference}, "
                          "not less than a method's error ${error}: it has not converged\n${out}")
    endif()
  endforeach()
  list(LENGTH euler count)
  if(count LESS 2)
    message(FATAL_ERROR "${scene}: fewer than two stable symplectic Euler runs\n${out}")
  endif()
  set(previous "")
  foreach(error IN LISTS euler)
    if(NOT previous STREQUAL "" AND NOT error LESS previous)
      message(FATAL_ERROR "${scene}: symplectic Euler's error ${error} did not fall below "
                          "${previous} as its step fell\n${out}")
    endif()
    set(previous ${error})
  endforeach()
endforeach()

check_plot(${WORK}/out/plot_methods.py ${WORK}/out/methods.svg "${err}")

# --speed on a small grid, and a scene passed by name (here one of the three again).
run_bench("bench methods --speed" bench methods --quick --no-plot --min-seconds 0.001 --speed
          --grid 16 --out speed ${SCENE})
file(STRINGS ${WORK}/speed/speed.csv speed)
list(LENGTH speed count)
list(GET speed 0 header)
# Seven measures (VBD's two among them), readable and engine room, on 1 and 2 threads:
# twenty-eight rows.
if(NOT count EQUAL 29 OR NOT header STREQUAL "grid,springs,measure,ns_per_spring,threads")
  message(FATAL_ERROR "speed.csv is not a header and twenty-eight rows:\n${speed}")
endif()
# A number, of either sign: an iteration's cost is the difference of two timings, and on a
# 16 x 16 grid a busy machine can make it negative (VBD's on 2 threads printed -20.458 once in
# CI, beside other tests on two cores), so a row's sign is no check of the bench. The shape is.
set(number "-?[0-9.]*[0-9](e[-+][0-9]+)?")
foreach(row "16,[0-9]+,xpbd-iteration,[-0-9.e]+,1" "16,[0-9]+,xpbd-iteration-readable,[-0-9.e]+,2"
        "16,[0-9]+,symplectic-euler-step,[0-9.e-]+,2"
        "16,[0-9]+,implicit-euler-cg-iteration,[0-9.e-]+,1"
        "16,[0-9]+,implicit-euler-cg-iteration-readable,[0-9.e-]+,2"
        "16,[0-9]+,local-global-iteration,[-0-9.e]+,2"
        "16,[0-9]+,local-global-iteration-readable,[-0-9.e]+,1"
        "16,[0-9]+,vbd-step-1-iteration-readable,${number},1"
        "16,[0-9]+,vbd-iteration-readable,${number},1"
        "16,[0-9]+,vbd-step-1-iteration-readable,${number},2"
        "16,[0-9]+,vbd-iteration-readable,${number},2"
        "16,[0-9]+,vbd-step-1-iteration,${number},1" "16,[0-9]+,vbd-iteration,${number},1"
        "16,[0-9]+,vbd-iteration,${number},2")
  set(found ${speed})
  list(FILTER found INCLUDE REGEX "^${row}$")
  if(NOT found)
    message(FATAL_ERROR "speed.csv has no row like ${row}:\n${speed}")
  endif()
endforeach()
# The bound on an XPBD iteration, measured in the same run, and VBD's printed row.
string(CONCAT bound "16 x 16: XPBD iteration / Euler step = [0-9.]+ [^\n]*\n"
       "(    bound on 2 threads[^\n]*\n)?    bound: the "
       "iteration's passes with no square root or division [^\n]* take ${number} ns per "
       "spring on 1 thread, ${number} Euler steps; ${number} on 2 threads; the XPBD "
       "iteration is ${number} times them\n")
if(NOT out MATCHES "${bound}")
  message(FATAL_ERROR "bench methods --speed printed no bound on an XPBD iteration:\n${out}")
endif()
# What bounds two threads, measured in the same run: the wakes of the threads counted, their
# cost, the speed-ups they allow, and this machine's own for a stream and for arithmetic. (On a
# 16 x 16 grid an XPBD iteration wakes none: no colour is large enough to split.)
string(CONCAT two_bound "2 threads over 1: Euler ${number}, XPBD ${number}\n    bound on 2 "
       "threads: an Euler step wakes the threads ${number} times, an XPBD iteration "
       "[0-9.]+, at ${number} ns a wake with nothing to do: with the rest split evenly, "
       "at most ${number} and ${number} times 1 thread; on this machine a stream gains "
       "${number} and square roots and divisions alone ${number}\n")
if(NOT out MATCHES "${two_bound}")
  message(FATAL_ERROR "bench methods --speed printed no bound on two threads:\n${out}")
endif()
string(CONCAT vbd "VBD \\(lesson 14\\)[^\n]*\n[^\n]*\n[^\n]*\n +16 x 16 +1 \\| +${number} "
       "+${number} \\| +${number} +${number} \\| +${number} \\| +${number} \\| "
       "+[-0-9.]+\n")
if(NOT out MATCHES "${vbd}")
  message(FATAL_ERROR "bench methods --speed printed no VBD row:\n${out}")
endif()
file(STRINGS ${WORK}/speed/methods.csv lines)
list(LENGTH lines count)
math(EXPR expected "${rows_per_scene} + 1")
if(NOT count EQUAL expected)
  message(FATAL_ERROR "one scene gave ${count} lines in methods.csv; expected ${expected}\n${out}")
endif()
