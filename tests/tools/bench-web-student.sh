#!/usr/bin/env bash
# bench-web-student.sh [BUILD_DIR] [EXERCISE_FILE]: edit-to-page for the student's live pages.
# What a student waits for between saving an exercise file and seeing it run in the browser:
# the file is edited (a comment that changes each time appended to it), then
#   cmake --build BUILD_DIR --target web-student
# rebuilds the student pages; timed from the edit to the build's end, and the student page of
# the exercise's lesson must then be newer than the edit. REPEATS times (default 3); prints each
# figure and the median, with the processor time the build took (user and system, its processes
# summed: about the wait on one idle core). The file is put back as it was at the end, whatever
# happens.
#
# Needs a build whose pages are built once already (configured with emscripten installed, then
# `cmake --build BUILD_DIR --target web-student`): what is measured is the loop, not the first
# build. BUILD_DIR defaults to build/, EXERCISE_FILE to exercises/02_spring_dampers.cpp. A
# benchmark, not a test: nothing here passes or fails on time.
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$source_dir/build}" && pwd)
exercise=${2:-$source_dir/exercises/02_spring_dampers.cpp}
repeats=${REPEATS:-3}
[[ -f $build/CMakeCache.txt ]] || { echo "bench-web-student: $build is not a build folder" >&2; exit 2; }
[[ -f $exercise ]] || { echo "bench-web-student: no $exercise" >&2; exit 2; }
# The lesson of exercises/NN_name.cpp is lessons/NN-*; its student page pages/NN-*-student.html.
number=$(basename "$exercise" | cut -c1-2)
lesson=$(cd "$source_dir/lessons" && ls -d "$number"-* | head -n 1)
page=$build/pages/$lesson-student.html
[[ -f $page ]] || {
  echo "bench-web-student: no $page: build the pages once first (cmake --build $build --target web-student)" >&2
  exit 2
}
saved=$(mktemp)
cp -p "$exercise" "$saved"
trap 'cp -p "$saved" "$exercise"; rm -f "$saved"' EXIT
log=$(mktemp /tmp/bench-web-student.XXXXXX.log)
now() { date +%s.%N; }
echo "edit-to-page: $(basename "$exercise") edited, then cmake --build $build --target web-student" \
  "($(nproc) cores; load $(cut -d' ' -f1 /proc/loadavg)); log in $log"
times=()
cpus=()
for ((k = 1; k <= repeats; ++k)); do
  cp -p "$saved" "$exercise"
  printf '\n// edited for bench-web-student.sh, round %d, %s\n' "$k" "$(date +%s%N)" >>"$exercise"
  start=$(now)
  if ! /usr/bin/time -f '%U %S' -o "$log.cpu" cmake --build "$build" --target web-student >>"$log" 2>&1; then
    echo "bench-web-student: the build failed (see $log)" >&2
    exit 1
  fi
  end=$(now)
  cpu=$(awk '{printf "%.1f", $1 + $2}' "$log.cpu")
  if [[ ! $page -nt $exercise ]]; then
    echo "bench-web-student: $page was not rewritten after the edit" >&2
    exit 1
  fi
  seconds=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.1f", b - a}')
  times+=("$seconds")
  cpus+=("$cpu")
  printf '  round %d: %5.1f s (processor time %.1f s)\n' "$k" "$seconds" "$cpu"
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
echo "edit-to-page (median of $repeats): $(median "${times[@]}") s, processor time $(median "${cpus[@]}") s"
