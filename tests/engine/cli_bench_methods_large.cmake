# `clothlab bench methods --large --quick`: the wiring of lesson 12's cloths of real size in
# seconds (one frame, one rung a method but RK4, a cheap reference; the real run takes many
# minutes). Each of the three large scenes gives its rows; each cloth is 48 x 48 or more, and
# symplectic Euler's advised step is 50 or more steps a frame of 1/60 s (the regime the large-step
# methods are for). Then the `bakeoff-update-lesson` script: it copies nothing when a file of the
# bake-off is missing, and all of them when they are there; and the `bakeoff` target writes into
# the build tree alone.
cmake_policy(VERSION 3.22)
include(${CMAKE_CURRENT_LIST_DIR}/cli_bench_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
# The reference by symplectic Euler (the engine room's, the cheapest step), to check --reference.
run_bench("bench methods --large --quick" bench methods --large --quick --no-plot
          --min-seconds 0.001 --reference symplectic-euler --out large)
# Per scene: the reference, then one rung each of symplectic Euler, implicit Euler, XPBD, VBD,
# and the local/global solver when the engine has it.
read_methods_csv(${WORK}/large/methods.csv 5 6)
set(frames 1)  # --quick --large
foreach(scene bakeoff-large-sheet bakeoff-large-flag bakeoff-large-drape)
  if(NOT out MATCHES "scene [^\n]*${scene}.toml: ${frames} frames[^\n]*\n[^\n]*\n[^\n]*\n  \
reference \\(symplectic-euler\\) ")
    message(FATAL_ERROR "${scene}: not run for ${frames} frames against a symplectic Euler "
                        "reference\n${out}")
  endif()
  # The cloth's size, from the scene file itself.
  file(READ ${LESSON}/${scene}.toml text)
  string(REGEX MATCH "\nrows = ([0-9]+)" _ "${text}")
  set(rows_of_cloth ${CMAKE_MATCH_1})
  string(REGEX MATCH "\ncols = ([0-9]+)" _ "${text}")
  if(rows_of_cloth LESS 48 OR CMAKE_MATCH_1 LESS 48)
    message(FATAL_ERROR "${scene}: ${rows_of_cloth} x ${CMAKE_MATCH_1} particles, not 48 x 48")
  endif()
  set(mine ${lines})
  list(FILTER mine INCLUDE REGEX "^${scene},")
  list(LENGTH mine rows)
  set(euler ${mine})
  list(FILTER euler INCLUDE REGEX "^${scene},symplectic-euler,")
  set(euler_steps "")
  if(euler MATCHES "^[^,]*,[^,]*,[^,]*,[^,]*,[^,]*,([0-9]+),")
    set(euler_steps ${CMAKE_MATCH_1})
  endif()
  if(NOT rows EQUAL rows_per_scene)
    message(FATAL_ERROR "${scene}: ${rows} rows in methods.csv; expected ${rows_per_scene}\n${out}")
  endif()
  math(EXPR least "50 * ${frames}")
  if(euler_steps STREQUAL "" OR euler_steps LESS least)
    message(FATAL_ERROR "${scene}: symplectic Euler's advised step takes '${euler_steps}' steps "
                        "over ${frames} frames, fewer than 50 a frame\n${out}")
  endif()
endforeach()

# bakeoff-update-lesson: with the large plot missing, it fails, says so and copies nothing.
set(from ${WORK}/from)
set(to ${WORK}/to)
file(MAKE_DIRECTORY ${to})
foreach(file bakeoff/methods.csv bakeoff/speed.csv bakeoff/methods.svg bakeoff-large/methods.csv)
  file(WRITE ${from}/${file} "${file}\n")
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -DFROM=${from} -DTO=${to} -P ${UPDATE_SCRIPT}
                RESULT_VARIABLE code OUTPUT_VARIABLE copy_out ERROR_VARIABLE copy_err)
file(GLOB copied ${to}/*)
if(code EQUAL 0 OR copied OR NOT copy_err MATCHES "bakeoff-large/methods.svg")
  message(FATAL_ERROR "bakeoff-update-lesson with a plot missing: exit ${code}, copied "
                      "'${copied}', said:\n${copy_out}${copy_err}")
endif()
file(WRITE ${from}/bakeoff-large/methods.svg "bakeoff-large/methods.svg\n")
execute_process(COMMAND ${CMAKE_COMMAND} -DFROM=${from} -DTO=${to} -P ${UPDATE_SCRIPT}
                RESULT_VARIABLE code OUTPUT_VARIABLE copy_out ERROR_VARIABLE copy_err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bakeoff-update-lesson failed with ${code}:\n${copy_out}${copy_err}")
endif()
foreach(pair "bakeoff/methods.csv=bakeoff.csv" "bakeoff/speed.csv=bakeoff-speed.csv"
        "bakeoff/methods.svg=bakeoff.svg" "bakeoff-large/methods.csv=bakeoff-large.csv"
        "bakeoff-large/methods.svg=bakeoff-large.svg")
  string(REPLACE "=" ";" pair "${pair}")
  list(GET pair 0 source)
  list(GET pair 1 target)
  if(NOT EXISTS ${to}/${target})
    message(FATAL_ERROR "bakeoff-update-lesson did not copy ${source} to ${target}")
  endif()
  file(READ ${to}/${target} text)
  if(NOT text STREQUAL "${source}\n")
    message(FATAL_ERROR "${target} holds '${text}', not ${source}")
  endif()
endforeach()

# The `bakeoff` target itself writes into the build tree only: its commands name no folder of
# the sources (the lesson's CSVs and plots change only through bakeoff-update-lesson).
get_filename_component(lessons ${UPDATE_SCRIPT} DIRECTORY)
file(READ ${lessons}/CMakeLists.txt lessons_cmake)
string(REGEX MATCH "add_custom_target\\(bakeoff\n[^)]*\\)" bakeoff "${lessons_cmake}")
if(bakeoff STREQUAL "" OR bakeoff MATCHES "SOURCE_DIR|12-xpbd")
  message(FATAL_ERROR "the bakeoff target is missing or writes into the sources:\n${bakeoff}")
endif()
