#!/usr/bin/env bash
# make_class.sh SOURCE OUT [N]: writes a class of N (default 50) generated submissions into OUT,
# a folder per student, for `clothlab grade --class OUT` (README, For instructors, measures the
# grading of such a class). Of every ten students:
#   0, 1  every exercise solved (copies of solutions/)
#   2     nothing handed in (every exercise graded on its shipped stub)
#   3     lessons 01 to 06 solved, the rest left as stubs
#   4-6   every exercise solved but one, with a planted mistake of
#         tests/grade/harness/planted/mutants.txt (a different one each time)
#   7     every exercise solved, one file that does not compile (a different one each time)
#   8     every exercise solved, Euler's step in an endless loop (its cases time out)
#   9     every exercise solved, Euler's step crashing (its cases crash)
set -euo pipefail
source_dir=$1
out=$2
n=${3:-50}
problem() { echo "make_class: $*" >&2; exit 2; }
source "$source_dir/tests/grade/harness/plant.sh"

# The planted mistakes: file|old line|new line.
mutants=()
file="" old=""
while IFS= read -r line; do
  if [[ $line =~ ^mutant\ ex[0-9.]+\ ([0-9][0-9]_[a-z_]+\.cpp): ]]; then
    file=${BASH_REMATCH[1]}
  elif [[ $line =~ ^-\ (.*)$ ]]; then
    old=${BASH_REMATCH[1]}
  elif [[ $line =~ ^\+\ (.*)$ ]]; then
    mutants+=("$file|$old|${BASH_REMATCH[1]}")
  fi
done <"$source_dir/tests/grade/harness/planted/mutants.txt"
solutions=("$source_dir"/solutions/[0-9][0-9]_*.cpp)
euler="const Vec3 a = f * inv_m;  // Newton: a = f / m"
# (What is planted goes before the comment, so that it is code.)

rm -rf "$out"
mkdir -p "$out"
for ((i = 0; i < n; ++i)); do
  dir=$out/$(printf 'student-%02d' "$i")
  mkdir -p "$dir"
  kind=$((i % 10))
  case $kind in
    2) continue ;;
    3) cp "${solutions[@]:0:6}" "$dir/" ;;
    *) cp "${solutions[@]}" "$dir/" ;;
  esac
  case $kind in
    4 | 5 | 6)
      IFS='|' read -r file old new <<<"${mutants[$(((i / 10 * 3 + kind - 4) % ${#mutants[@]}))]}"
      plant_line "$dir/$file" "$old" "$new" ;;
    7)
      broken=${solutions[$((i / 10 % ${#solutions[@]}))]}
      printf '\nint broken_on_purpose( {\n' >>"$dir/$(basename "$broken")" ;;
    8) plant_line "$dir/01_particles_and_euler.cpp" "$euler" \
      "const Vec3 a = f * inv_m; while (true) { static volatile int spin; spin = spin + 1; }" ;;
    9) plant_line "$dir/01_particles_and_euler.cpp" "$euler" "const Vec3 a = f * inv_m; __builtin_trap();" ;;
  esac
done
echo "make_class: $n submissions in $out"
