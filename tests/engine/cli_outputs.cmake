# `clothlab run` loses nothing: a full disk (here a file size limit, which fails a write the
# same way) and a TERM each leave whole frames, the same in every file, and say what happened;
# a folder or a page of the user's is refused, and kept as it was.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/cloth.toml "title = \"outputs test\"
[cloth]
rows = 40
cols = 40
spacing = 0.03
mass = 0.5
pins = \"top-corners\"
[springs]
ks = 100
kd = 0.01
[gravity]
[integrator]
dt = 0.0005
duration = DURATION
[output]
fps = FPS
velocities = true
")
file(READ ${WORK}/cloth.toml text)
string(REPLACE "DURATION" "0.5" short "${text}")
string(REPLACE "FPS" "100" short "${short}")
string(REPLACE "DURATION" "600" long "${text}")
string(REPLACE "FPS" "5" long "${long}")
file(WRITE ${WORK}/short.toml "${short}")
file(WRITE ${WORK}/long.toml "${long}")

# Every file ends with a whole line, and all of them hold the same frames: `frames` of them.
function(check_whole_frames dir frames)
  foreach(name energy positions velocities)
    file(READ ${dir}/${name}.csv content)
    string(LENGTH "${content}" length)
    math(EXPR last "${length} - 1")
    string(SUBSTRING "${content}" ${last} 1 end)
    if(NOT end STREQUAL "\n")
      message(FATAL_ERROR "${name}.csv ends in a cut line")
    endif()
  endforeach()
  file(STRINGS ${dir}/energy.csv rows)
  list(LENGTH rows count)
  math(EXPR written "${count} - 1")
  if(NOT written EQUAL frames)
    message(FATAL_ERROR "energy.csv holds ${written} frames, expected ${frames}")
  endif()
  foreach(name positions velocities)
    file(STRINGS ${dir}/${name}.csv rows)
    list(LENGTH rows count)
    math(EXPR expected "1 + ${frames} * 1600")
    if(NOT count EQUAL expected)
      message(FATAL_ERROR "${name}.csv has ${count} lines, expected ${expected} (${frames} frames)")
    endif()
    list(GET rows -1 last_row)
    string(REPLACE "," ";" cells "${last_row}")
    list(LENGTH cells fields)
    if(NOT fields EQUAL 6)
      message(FATAL_ERROR "${name}.csv's last row has ${fields} fields: ${last_row}")
    endif()
  endforeach()
endfunction()

# A full disk: the files stop at a whole frame and the message names the file and the reason.
execute_process(COMMAND prlimit --fsize=3000000 -- ${CLOTHLAB} run ${WORK}/short.toml
                        --out ${WORK}/full
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 1)
  message(FATAL_ERROR "expected exit code 1 on a full disk, got ${code}\n${out}${err}")
endif()
if(NOT err MATCHES "error: writing [^\n]*/full/(positions|velocities)\\.csv failed: File too large")
  message(FATAL_ERROR "the message does not name the file and the reason:\n${err}")
endif()
if(NOT err MATCHES "the frames before it are whole in [^\n]*/full/")
  message(FATAL_ERROR "the message does not say where the whole frames are:\n${err}")
endif()
file(STRINGS ${WORK}/full/energy.csv rows)
list(LENGTH rows count)
math(EXPR frames "${count} - 1")
if(frames LESS 1 OR frames GREATER 40)
  message(FATAL_ERROR "unexpected ${frames} frames before the limit")
endif()
check_whole_frames(${WORK}/full ${frames})

# A TERM in the middle of a long run: it stops after the step, writes that step as a last
# frame, and the page. (--foreground: timeout signals the run alone. Without it, it signals the
# run and then its own process group, the run again: a second TERM that comes after the first was
# handled ends the run at once, as a second Ctrl-C does, with 143.)
execute_process(COMMAND timeout --foreground --preserve-status -s TERM 2 ${CLOTHLAB} run
                        ${WORK}/long.toml
                        --out ${WORK}/term
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 130)
  message(FATAL_ERROR "expected exit code 130 after a TERM, got ${code}\n${out}${err}")
endif()
if(NOT err MATCHES "stopped by SIGTERM after step [0-9]+ \\(t = [0-9.e+-]+ s\\): ([0-9]+) frames, the last at that step, are in [^\n]*/term/ and the page [^\n]*view.html shows them")
  message(FATAL_ERROR "unexpected message after a TERM:\n${err}")
endif()
set(frames ${CMAKE_MATCH_1})
check_whole_frames(${WORK}/term ${frames})
file(READ ${WORK}/term/view.html page)
if(NOT page MATCHES "outputs test")
  message(FATAL_ERROR "the page of the stopped run is missing")
endif()

# A TERM during the start-up work ([gravitation]'s first energy of 40000 particles takes
# seconds): said at once, and the run ends cleanly (130), not killed by the signal (143).
file(WRITE ${WORK}/gravitation.toml "[cloth]
rows = 200
cols = 200
spacing = 0.01
mass = 1
[gravitation]
[integrator]
dt = 0.001
duration = 1
")
execute_process(COMMAND timeout --foreground --preserve-status -s TERM 1 ${CLOTHLAB} run
                        ${WORK}/gravitation.toml --out ${WORK}/gravitation
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 130 OR NOT err MATCHES "\nstopping after this step[^\n]*\nstopped by SIGTERM (before the first step|before the first frame|during step 1)")
  message(FATAL_ERROR "a TERM during the start-up work (exit ${code}):\n${out}${err}")
endif()

# A folder of the user's, and a page of the user's: refused, and left as they were.
file(MAKE_DIRECTORY ${WORK}/mine)
file(WRITE ${WORK}/mine/positions.csv "my own data\n")
execute_process(COMMAND ${CLOTHLAB} run ${WORK}/short.toml --out ${WORK}/mine
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 2 OR NOT err MATCHES "is not a clothlab output folder: it holds positions.csv")
  message(FATAL_ERROR "a folder of the user's was not refused (${code}):\n${out}${err}")
endif()
file(READ ${WORK}/mine/positions.csv kept)
file(GLOB left ${WORK}/mine/*)
if(NOT kept STREQUAL "my own data\n" OR NOT left STREQUAL "${WORK}/mine/positions.csv")
  message(FATAL_ERROR "the user's folder was changed: ${left}")
endif()
file(WRITE ${WORK}/notes.html "my notes")
execute_process(COMMAND ${CLOTHLAB} run ${WORK}/short.toml --out ${WORK}/run --html
                        ${WORK}/notes.html
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT code EQUAL 2 OR NOT err MATCHES "notes.html exists and is not a clothlab viewer page")
  message(FATAL_ERROR "a page of the user's was not refused (${code}):\n${out}${err}")
endif()
file(READ ${WORK}/notes.html kept)
if(NOT kept STREQUAL "my notes" OR EXISTS ${WORK}/run)
  message(FATAL_ERROR "a refused run wrote something")
endif()
# --force writes into the folder, replacing only clothlab's names.
file(WRITE ${WORK}/mine/notes.txt "keep\n")
execute_process(COMMAND ${CLOTHLAB} run ${WORK}/short.toml --out ${WORK}/mine --force
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
file(READ ${WORK}/mine/notes.txt kept)
if(NOT code EQUAL 0 OR NOT kept STREQUAL "keep\n")
  message(FATAL_ERROR "--force failed (${code}) or lost the user's file:\n${out}${err}")
endif()
check_whole_frames(${WORK}/mine 51)
