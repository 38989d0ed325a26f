#!/usr/bin/env bash
# bench-student-loop.sh [WORK_DIR]: what a student waits for, measured on a fresh copy of this
# checkout (its tracked files and new ones, as they are in the working tree):
#   1. first run: the Quick start's build (configure, then the student preset), then the first
#      graded exercise (`clothlab grade --exercise ex01.1`);
#   2. the loop: an exercise file edited (solved, made wrong, broken, mended), then graded, for
#      one exercise and for all of them, with nothing rebuilt by hand;
#   3. a student program: its first run (which builds it), then an edit and a run (its launcher
#      rebuilds it first);
#   4. what the student build gives up for it: `clothlab bench speed` on a 64 x 64 cloth, the
#      reference build and the student build (its exercises solved) taking turns in one run.
# Prints each figure as it is measured, then a summary. Needs the packages of the Quick start;
# takes a few minutes on two cores. A benchmark, not a test: nothing here passes or fails on time.
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
work=${1:-$(mktemp -d /tmp/clothlab-loop.XXXXXX)}
repeats=${REPEATS:-3}
copy=$work/clothlab
rm -rf "$copy"
mkdir -p "$copy"
(cd "$source_dir" && git ls-files -z --cached --others --exclude-standard |
  xargs -0 cp --parents -t "$copy" 2>/dev/null) || true
[[ -f $copy/CMakeLists.txt ]] || {
  echo "bench-student-loop: copying the checkout failed" >&2
  exit 2
}
cd "$copy"
summary=()
now() { date +%s.%N; }
# timed NAME COMMAND...: runs the command (output to a log) and records its wall time.
timed() {
  local name=$1
  shift
  local start end
  start=$(now)
  "$@" >>"$work/bench.log" 2>&1 || true
  end=$(now)
  last=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.3f", b - a}')
  printf '  %-58s %7.2f s\n' "$name" "$last"
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
grade() { NO_COLOR=1 ./build/clothlab grade "$@"; }

echo "== 1. first run, on a fresh copy ($(nproc) cores)"
first_start=$(now)
timed "configure (cmake --preset default)" cmake --preset default
configure=$last
timed "build the student preset (cmake --build --preset student)" cmake --build --preset student
build=$last
timed "first grade (clothlab grade --exercise ex01.1)" grade --exercise ex01.1
first_grade=$last
first_total=$(awk -v a="$first_start" -v b="$(now)" 'BEGIN {printf "%.3f", b - a}')
printf '  %-58s %7.2f s\n' "fresh copy to the first graded exercise" "$first_total"
summary+=("$(printf 'fresh copy to the first graded exercise: %.0f s (configure %.0f s, build %.0f s, grade %.1f s)' \
  "$first_total" "$configure" "$build" "$first_grade")")

echo "== 2. the loop: edit one exercise file, then grade"
ex01=exercises/01_particles_and_euler.cpp
ex02=exercises/02_spring_dampers.cpp
cp "$ex01" "$work/01.stub"
cp "$ex02" "$work/02.stub"
one=() all=() broken=()
for round in $(seq "$repeats"); do
  cp solutions/01_particles_and_euler.cpp "$ex01"
  timed "round $round: ex01 solved, grade --exercise ex01.3" grade --exercise ex01.3
  one+=("$last")
  sed -i 's/return {r + v \* dt, v + a \* dt};/return {r + (v + a * dt) * dt, v + a * dt};/' "$ex01"
  timed "round $round: ex01.3 made wrong, grade --exercise ex01.3" grade --exercise ex01.3
  one+=("$last")
  cp solutions/02_spring_dampers.cpp "$ex02"
  timed "round $round: ex02 solved, grade (every exercise)" grade
  all+=("$last")
  sed -i 's/return m \* g;/return m * g/' "$ex01"
  timed "round $round: ex01 broken (a missing ';'), grade" grade
  broken+=("$last")
  cp "$work/01.stub" "$ex01"
  cp "$work/02.stub" "$ex02"
  timed "round $round: back to the stubs, grade" grade
  all+=("$last")
done
summary+=("$(printf 'edit, then grade one exercise: median %.2f s (most %.2f s) over %d edits' \
  "$(median "${one[@]}")" "$(printf '%s\n' "${one[@]}" | sort -g | tail -1)" "${#one[@]}")")
summary+=("$(printf 'edit, then grade every exercise: median %.2f s (most %.2f s) over %d edits' \
  "$(median "${all[@]}")" "$(printf '%s\n' "${all[@]}" | sort -g | tail -1)" "${#all[@]}")")
summary+=("$(printf 'a file that does not compile, then grade every exercise: median %.2f s' \
  "$(median "${broken[@]}")")")

echo "== 3. the student programs: built on demand, brought up to date by their launchers"
timed "first run of ./build/clothlab-student (builds it)" ./build/clothlab-student --help
summary+=("$(printf 'the first run of clothlab-student, which builds it: %.0f s' "$last")")
launch=()
for round in $(seq "$repeats"); do
  cp solutions/01_particles_and_euler.cpp "$ex01"
  timed "round $round: ex01 solved, ./build/clothlab-student --help" ./build/clothlab-student --help
  launch+=("$last")
  cp "$work/01.stub" "$ex01"
  timed "round $round: back to the stub, ./build/clothlab-student --help" ./build/clothlab-student --help
  launch+=("$last")
done
summary+=("$(printf 'edit one exercise file, then run clothlab-student (rebuilt first): median %.2f s (most %.2f s)' \
  "$(median "${launch[@]}")" "$(printf '%s\n' "${launch[@]}" | sort -g | tail -1)")")

echo "== 4. the student build's steps against the reference build's (64 x 64 cloth)"
cp solutions/[0-9][0-9]_*.cpp exercises/
timed "build clothlab-student on the solved exercises" cmake --build build --target clothlab-student
NO_COLOR=1 ./build/clothlab bench speed --sizes 64 --variants reference,student --threads 1 \
  --repeats 5 | tee "$work/speed.txt"
ref=$(awk '$3 == "reference" && $4 == "1" {print $5; exit}' "$work/speed.txt")
stu=$(awk '$3 == "student" && $4 == "1" {print $5; exit}' "$work/speed.txt")
if [[ -n $ref && -n $stu ]]; then
  summary+=("$(printf 'a 64 x 64 step, 1 thread: student build %s ns per spring-step, reference %s ns: %.2f times as long' \
    "$stu" "$ref" "$(awk -v a="$stu" -v b="$ref" 'BEGIN {print a / b}')")")
fi

echo
echo "== summary (log: $work/bench.log)"
printf '  %s\n' "${summary[@]}"
