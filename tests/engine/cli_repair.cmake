# A refused `clothlab run` or `clothlab repair` changes no file: --html onto the run's own data
# or its folder, onto a file of the user's in the folder, a file of the user's named frames; a
# folder that is not a run's, a file repair cannot read. And what repair says is what the files
# hold.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/drop.toml "title = \"repair test\"
[[particle]]
position = [0, 0, 0]
mass = 1
[[particle]]
position = [1, 0, 0]
mass = 1
[[spring]]
i = 0
j = 1
ks = 10
[gravity]
[integrator]
dt = 0.01
duration = 0.5
[output]
fps = 100
velocities = true
")

# Runs clothlab with ARGN, expecting exit code `code` and stderr matching `pattern`.
function(expect code pattern)
  execute_process(COMMAND ${CLOTHLAB} ${ARGN} RESULT_VARIABLE got ERROR_VARIABLE err
                  OUTPUT_VARIABLE out)
  if(NOT got EQUAL code OR NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "clothlab ${ARGN}: exit ${got}, expected ${code} and \"${pattern}\":\n"
                        "${out}${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

# The files of ${WORK}/run as they are now, to compare with later.
function(snapshot var)
  set(all "")
  file(GLOB names RELATIVE ${WORK}/run ${WORK}/run/* ${WORK}/run/.clothlab-run)
  list(SORT names)
  foreach(name ${names})
    file(SHA256 ${WORK}/run/${name} hash)
    string(APPEND all "${name} ${hash}\n")
  endforeach()
  set(${var} "${all}" PARENT_SCOPE)
endfunction()
function(expect_unchanged before what)
  snapshot(now)
  if(NOT now STREQUAL before)
    message(FATAL_ERROR "${what} changed the run's folder:\n${before}\nnow:\n${now}")
  endif()
endfunction()

expect(0 "" run ${WORK}/drop.toml --out ${WORK}/run)
file(WRITE ${WORK}/run/notes.txt "mine\n")
snapshot(first)

# --html onto the run's own data, into a new folder and into this one.
expect(2 "error: --html [^\n]*/new/positions.csv is the run's own positions.csv in --out [^\n]*/new, and the page would replace it"
       run ${WORK}/drop.toml --out ${WORK}/new --html ${WORK}/new/positions.csv)
expect(2 "is the run's own energy.csv in --out"
       run ${WORK}/drop.toml --out ${WORK}/run --html ${WORK}/run/energy.csv)
# --html as the --out folder itself.
expect(2 "error: --html [^\n]*/new is the --out folder [^\n]*/new, and the page is a file"
       run ${WORK}/drop.toml --out ${WORK}/new --html ${WORK}/new)
if(EXISTS ${WORK}/new)
  message(FATAL_ERROR "a refused run made its folder")
endif()
# --html onto the user's note in the folder: refused before the last run's files are cleared.
expect(2 "notes.txt exists and is not a clothlab viewer page[^\n]*\n  nothing was run"
       run ${WORK}/drop.toml --out ${WORK}/run --html ${WORK}/run/notes.txt)
expect_unchanged("${first}" "a run refused for its --html")

# A file of the user's named frames: refused, with or without --force, and kept.
file(WRITE ${WORK}/run/frames "my notes on these frames\n")
snapshot(with_frames)
expect(2 "error: [^\n]*/run/frames is a file, not the folder of mesh frames"
       run ${WORK}/drop.toml --out ${WORK}/run)
expect(2 "is a file, not the folder of mesh frames" run ${WORK}/drop.toml --out ${WORK}/run
       --force --obj)
expect_unchanged("${with_frames}" "a run refused for a file named frames")
file(REMOVE ${WORK}/run/frames)

# repair: a folder of the user's (no marker) is refused and kept.
file(MAKE_DIRECTORY ${WORK}/mine)
file(WRITE ${WORK}/mine/energy.csv "frame,t\n0,0\n1,0.1\n")
file(WRITE ${WORK}/mine/positions.csv "frame,t,particle,x,y,z\n0,0,0,1,2,3\n1,0.1,0,1,2,3\n2,0.2,0,1,2,3\n")
expect(2 "error: [^\n]*/mine is not a clothlab output folder: it holds no .clothlab-run marker"
       repair ${WORK}/mine)
file(READ ${WORK}/mine/positions.csv kept)
if(NOT kept STREQUAL "frame,t,particle,x,y,z\n0,0,0,1,2,3\n1,0.1,0,1,2,3\n2,0.2,0,1,2,3\n")
  message(FATAL_ERROR "repair changed a folder of the user's:\n${kept}")
endif()

# repair: an energy.csv it cannot read is refused, and no file is cut.
file(READ ${WORK}/run/energy.csv energy_text)
file(WRITE ${WORK}/run/energy.csv "garbage\n")
snapshot(garbage)
expect(2 "energy.csv is not a file of frames as clothlab writes it: its first line is not the header"
       repair ${WORK}/run)
expect_unchanged("${garbage}" "a refused repair")
file(WRITE ${WORK}/run/energy.csv "${energy_text}")

# repair: velocities.csv lost its end (frame 11 holds particle 0 only): every file is cut to
# frames 0 to 10, as it says.
file(STRINGS ${WORK}/run/velocities.csv rows)
list(SUBLIST rows 0 24 kept)  # the header, frames 0 to 10 (two rows each) and a row of 11
list(JOIN kept "\n" text)
file(WRITE ${WORK}/run/velocities.csv "${text}\n")
expect(0 "" repair ${WORK}/run)
if(NOT out MATCHES "every file holds frames 0 to 10 \\(11 frames\\)")
  message(FATAL_ERROR "repair said:\n${out}")
endif()
foreach(name energy positions velocities)
  file(STRINGS ${WORK}/run/${name}.csv rows)
  list(LENGTH rows count)
  list(GET rows -1 last)
  if(name STREQUAL "energy")
    set(expected 12)
  else()
    set(expected 23)
  endif()
  if(NOT count EQUAL expected OR NOT last MATCHES "^10,")
    message(FATAL_ERROR "${name}.csv has ${count} lines after repair, expected ${expected}, the last ${last}")
  endif()
endforeach()
