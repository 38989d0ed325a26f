#!/usr/bin/env bash
# check-release.sh BUILD_DIR [WORK_DIR]: exports the student release from a built project and
# checks it the way a student meets it, on a fresh copy:
#   - no solutions/, no hidden tests, exercises/ are the shipped stubs, a Classroom workflow;
#   - it configures and builds with plain CMake;
#   - the stubs grade zero and a scene stops naming the unfinished exercise;
#   - with every exercise solved, it grades full marks and the scenes run on the student's code.
# With --gradescope it also unpacks the Gradescope autograder, runs its setup.sh and grades a
# submission with its run_autograder (setup.sh installs packages with apt-get when run as root).
set -euo pipefail
gradescope=0
if [[ ${1:-} == --gradescope ]]; then
  gradescope=1
  shift
fi
if [[ $# -lt 1 ]]; then
  echo "usage: $0 [--gradescope] BUILD_DIR [WORK_DIR]" >&2
  exit 2
fi
source_dir=$(cd "$(dirname "$0")/../../.." && pwd)
build=$(cd "$1" && pwd)
work=${2:-$build/release-check}
jobs=$(nproc)
rm -rf "$work"
mkdir -p "$work"
say() { printf '\n== %s\n' "$*"; }
die() {
  echo "check-release: $*" >&2
  exit 1
}

say "exporting the student release"
cmake --build "$build" --target student-release
release=$work/student
cp -r "$build/student-release" "$release"

[[ ! -e $release/solutions ]] || die "the release has solutions/"
[[ ! -e $release/tests/grade-hidden ]] || die "the release has the hidden tests"
[[ ! -e $release/tests/grade/harness/planted ]] ||
  die "the release has tests/grade/harness/planted/, which quotes lines of the solutions"
[[ ! -e $release/.ci ]] || die "the release has our CI"
for exercise in "$release"/exercises/[0-9][0-9]_*.cpp; do
  grep -q CLOTHLAB_TODO "$exercise" || die "$exercise is not a stub"
  "$build/clothlab-stubgen" "$exercise" "$work/restub.cpp"
  cmp -s "$exercise" "$work/restub.cpp" || die "$exercise is not exactly the shipped stub"
done
workflow=$release/.github/workflows/classroom.yml
[[ -f $workflow ]] || die "the release has no Classroom workflow"
steps=$(grep -c 'uses: classroom-resources/autograding-command-grader@v1' "$workflow")
exercises=$(NO_COLOR=1 "$build/clothlab" grade --impl stubs --list |
  awk '/^ex[0-9]/ && $NF == "visible" {print $1}' | sort -u | wc -l)
[[ $steps -eq $exercises ]] || die "the workflow has $steps steps for $exercises exercises"

# Link-time optimisation is off here: the default build already links these sources with it,
# and without it this check takes about half the time. So are the live pages: the default
# build makes and tests the same pages on the same stubs, and compiling the engine to
# WebAssembly again would add minutes.
say "building the release as a student would (plain cmake, without link-time optimisation)"
cmake -S "$release" -B "$release/build" -DCLOTHLAB_LTO=OFF -DCLOTHLAB_WEB=OFF \
  >"$work/configure.log" || {
  cat "$work/configure.log"
  die "the release does not configure"
}
cmake --build "$release/build" --parallel "$jobs" >"$work/build.log" 2>&1 || {
  tail -50 "$work/build.log"
  die "the release does not build"
}
ctest --test-dir "$release/build" --output-on-failure -j "$jobs"

say "the shipped stubs grade zero; a scene names the unfinished exercise"
(cd "$release" && NO_COLOR=1 ./build/clothlab grade --require-zero)
if (cd "$release" && ./build/clothlab-student run lessons/01-particles-and-euler/projectile.toml \
  --out "$work/stub-run") >"$work/stub-run.log" 2>&1; then
  die "a scene ran on the stubs"
fi
grep -q "ex01.1 is not implemented yet" "$work/stub-run.log" ||
  die "the stopped scene does not name ex01.1: $(cat "$work/stub-run.log")"

say "with every exercise solved: full marks, and the scenes run on the student's code"
# Nothing is rebuilt by hand: the grader builds the exercises as saved, and each student
# program's launcher brings the program up to date before it runs.
cp "$source_dir"/solutions/[0-9][0-9]_*.cpp "$release/exercises/"
(cd "$release" && NO_COLOR=1 ./build/clothlab grade --require-full)
(cd "$release" && ./build/clothlab-student run lessons/02-spring-dampers/hanging-cloth.toml \
  --out "$work/solved-run")
(cd "$release" && ./build/lesson02-student >/dev/null)

say "an edit that does not compile: no stale grade, no stale program"
ex01=$release/exercises/01_particles_and_euler.cpp
sed -i 's/return m \* g;/return m * g/' "$ex01"
grep -q 'return m \* g$' "$ex01" || die "the planted typo is not in $ex01"
out=$(cd "$release" && NO_COLOR=1 ./build/clothlab grade) || true
grep -Eq '^ex01\.1 +0 / 2 +0 / 2 +not compiled' <<<"$out" || die "a broken ex01 was graded: $out"
grep -Eq 'exercises/01_particles_and_euler\.cpp:[0-9]+:[0-9]+: error:' <<<"$out" ||
  die "the grader does not show the compiler's error: $out"
grep -Eq '^ex02\.1 +[0-9]+ / [0-9]+ +[0-9]+ / [0-9]+ +done' <<<"$out" ||
  die "ex02 was not graded beside the broken ex01: $out"
if (cd "$release" && ./build/lesson01-student) >"$work/stale.log" 2>&1; then
  die "lesson01-student ran code older than the broken exercise file"
fi
grep -q 'nothing was run' "$work/stale.log" || die "lesson01-student does not say why: $(cat "$work/stale.log")"
cp "$source_dir"/solutions/01_particles_and_euler.cpp "$ex01"
(cd "$release" && NO_COLOR=1 ./build/clothlab grade --exercise ex01 --require-full)
(cd "$release" && ./build/lesson01-student >/dev/null)

if [[ $gradescope -eq 1 ]]; then
  say "the Gradescope autograder: setup.sh, then run_autograder on a submission"
  cmake --build "$build" --target gradescope-autograder
  root=$work/autograder
  mkdir -p "$root/source" "$root/submission"
  (cd "$root/source" && cmake -E tar xf "$build/gradescope-autograder.zip")
  if [[ $(id -u) -eq 0 ]]; then
    AUTOGRADER_ROOT=$root bash "$root/source/setup.sh" >"$work/setup.log" 2>&1 || {
      tail -50 "$work/setup.log"
      die "setup.sh failed"
    }
    for secret in tests/grade-hidden build/grade-cases; do
      mode=$(stat -c %A "$root/source/clothlab/$secret")
      [[ $mode == ????------ ]] || die "setup.sh leaves $secret open to other users ($mode)"
    done
  else
    echo "(not root: building the autograder without its apt-get step)"
    (cd "$root/source/clothlab" && cmake -S . -B build >/dev/null &&
      cmake --build build --parallel "$jobs" --target clothlab grade-kit >/dev/null)
  fi
  cp "$source_dir"/solutions/01_*.cpp "$source_dir"/solutions/02_*.cpp "$root/submission/"
  AUTOGRADER_ROOT=$root bash "$root/source/run_autograder"
  results=$root/results/results.json
  [[ -f $results ]] || die "run_autograder wrote no results.json"
  expected=$(NO_COLOR=1 "$root/source/clothlab/build/clothlab" grade --impl stubs --list |
    awk '/^ex0[12]\./ {sum += $(NF-1)} END {print sum}')
  score=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["score"])' \
    "$results")
  [[ $score -eq $expected ]] || die "the autograder scored $score, expected $expected"
  grep -q '"visibility": "after_due_date"' "$results" ||
    die "results.json has no hidden test (after_due_date)"
fi

say "the student release checks out"
