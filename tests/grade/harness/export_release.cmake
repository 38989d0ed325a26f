# export_release.cmake: writes the student release of the project, or the Gradescope autograder.
#
#   cmake -DSOURCE=<project source> -DOUT=<folder> -DSTUBGEN=<clothlab-stubgen>
#         -DCLOTHLAB=<clothlab> [-DGRADESCOPE=ON] -P export_release.cmake
#
# The student release is the starter repository: the engine, the lessons, the grading tests and
# exercises/ as shipped stubs (regenerated from the exercise files, so an instructor's own
# answers never leak into it); no solutions/, no tests/grade-hidden/, no CI of ours. It gets a
# GitHub Classroom workflow with one step per exercise, written from the points table.
#
# With GRADESCOPE=ON, OUT gets Gradescope's autograder instead: setup.sh and run_autograder at
# the top and the release, hidden tests included, in clothlab/; and OUT.zip of the three.
cmake_minimum_required(VERSION 3.22)

foreach(var SOURCE OUT STUBGEN CLOTHLAB)
  if(NOT ${var})
    message(FATAL_ERROR "export_release.cmake needs -D${var}=...")
  endif()
endforeach()

file(REMOVE_RECURSE ${OUT})
if(GRADESCOPE)
  set(tree ${OUT}/clothlab)
else()
  set(tree ${OUT})
endif()
file(MAKE_DIRECTORY ${tree})

# What a student gets: the files the project tracks under these names, never build folders.
foreach(file CMakeLists.txt CMakePresets.json README.md course.toml .clang-format .gitignore)
  if(EXISTS ${SOURCE}/${file})
    file(COPY ${SOURCE}/${file} DESTINATION ${tree})
  endif()
endforeach()
# tests/grade/harness/planted/ holds lines of the solutions (the mistakes are planted in copies of them),
# and its tests run only where solutions/ is.
foreach(dir engine lessons tests)
  file(COPY ${SOURCE}/${dir} DESTINATION ${tree}
       PATTERN "__pycache__" EXCLUDE
       PATTERN "grade-hidden" EXCLUDE
       PATTERN "planted" EXCLUDE)
endforeach()
if(GRADESCOPE AND EXISTS ${SOURCE}/tests/grade-hidden)
  file(COPY ${SOURCE}/tests/grade-hidden DESTINATION ${tree}/tests)
endif()

# exercises/: the shipped stubs, whatever the instructor's copy holds.
file(MAKE_DIRECTORY ${tree}/exercises)
file(COPY ${SOURCE}/exercises/CMakeLists.txt DESTINATION ${tree}/exercises)
file(GLOB exercises ${SOURCE}/exercises/[0-9][0-9]_*.cpp)
foreach(exercise ${exercises})
  get_filename_component(name ${exercise} NAME)
  execute_process(COMMAND ${STUBGEN} ${exercise} ${tree}/exercises/${name}
                  RESULT_VARIABLE code ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "stubgen failed on exercises/${name}: ${err}")
  endif()
endforeach()

# The README says what this copy is.
file(READ ${tree}/README.md readme)
file(WRITE ${tree}/README.md
"> **Student release.** This copy has no `solutions/` and no hidden grading tests: every
> program here, `clothlab` as well as `clothlab-student`, runs on your `exercises/`, so a scene
> runs once the exercises its effects need are done (until then it stops and names the
> exercise). `./build/clothlab grade` scores your work as saved; `--impl reference` is not
> available. `./build/clothlab-student` and `./build/lessonNN-student` bring themselves up to
> date before they run; `./build/clothlab` runs what `cmake --build build` last built.

${readme}")

if(NOT GRADESCOPE)
  file(MAKE_DIRECTORY ${tree}/.github/workflows)
  execute_process(COMMAND ${CLOTHLAB} grade --impl stubs --classroom
                          ${tree}/.github/workflows/classroom.yml
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "writing the GitHub Classroom workflow failed: ${out}${err}")
  endif()
  message("Wrote the student release to ${OUT}")
  return()
endif()

# --- Gradescope ---------------------------------------------------------------------------------
file(WRITE ${OUT}/setup.sh [=[#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image: it installs the
# packages clothlab needs and builds the engine, the grading tests and the grader. Each
# submission then compiles only its exercise files (see run_autograder). Choose a Debian 12 or
# Ubuntu 24.04 (or later) base image: Ubuntu 22.04 has no libtomlplusplus-dev.
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive
root=${AUTOGRADER_ROOT:-/autograder}
apt-get update
# Every package the top CMakeLists.txt requires (a test checks this list against it), and
# bubblewrap for the grader's sandbox.
apt-get install -y --no-install-recommends g++ cmake make libeigen3-dev doctest-dev libfmt-dev \
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libsuitesparse-dev bubblewrap
cd "$root/source/clothlab"
# Gradescope builds the image on one machine and grades on others, whose processors may lack
# what -march=native would use here (a kernel would then die of SIGILL): a portable build.
cmake -S . -B build -DCLOTHLAB_NATIVE=OFF
cmake --build build --parallel "$(nproc)" --target clothlab grade-kit
# A submission's code runs as the user nobody (and in a sandbox where the container allows one):
# the hidden tests' sources, the grading binary and the objects that hold them and the lists of
# their names are root's alone (the grader, as root, sees to it again each time it grades).
chmod -R go-rwx tests/grade-hidden build/grade-cases \
  build/tests/grade/CMakeFiles/clothlab_grade_tests.dir build/tests/grade/grade-cases_* \
  2>/dev/null || true
]=])
file(WRITE ${OUT}/run_autograder [=[#!/usr/bin/env bash
# Gradescope runs this for every submission: it grades the exercise files in
# /autograder/submission (at its top or in an exercises/ folder; a missing file counts as the
# shipped stub) and writes /autograder/results/results.json, hidden cases included. Each case
# runs in its own process with a timeout; a file that does not compile costs its own exercises
# only, with the compiler's error. The summary at the top of results.json, which a student sees at
# once, shows only the visible cases.
set -uo pipefail
root=${AUTOGRADER_ROOT:-/autograder}
mkdir -p "$root/results"
cd "$root/source/clothlab"
NO_COLOR=1 ./build/clothlab grade --submission "$root/submission" \
  --scratch "$root/source/clothlab/build/submission" --results "$root/results/results.json" \
  --hidden
]=])
file(CHMOD ${OUT}/setup.sh ${OUT}/run_autograder
     PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ
                 WORLD_EXECUTE)
execute_process(COMMAND ${CMAKE_COMMAND} -E tar cf ${OUT}.zip --format=zip setup.sh
                        run_autograder clothlab
                WORKING_DIRECTORY ${OUT} RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "zipping the autograder failed")
endif()
message("Wrote the Gradescope autograder to ${OUT}.zip (its files are in ${OUT})")
