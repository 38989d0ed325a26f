#!/usr/bin/env bash
# check_student_loop.sh CLOTHLAB SOURCE WORK_DIR: the student's loop, on a folder of exercise
# files of its own (as `clothlab grade` builds exercises/, through the same code):
#   - a grade is always that of the files as saved: solved, then wrong, then not compiling, with
#     nothing rebuilt by hand in between;
#   - a file that does not compile costs its own exercises only, and shows the compiler's error;
#   - every failing case of an exercise gets a line, the first one the whole story;
#   - hidden cases are out of a student's grade and list, in with --hidden;
#   - `clothlab watch` grades again when a file is saved.
set -euo pipefail
clothlab=$1
source_dir=$2
work=$3
rm -rf "$work"
mkdir -p "$work/exercises"
die() {
  echo "check_student_loop: $*" >&2
  exit 1
}
source "$(dirname "$0")/watch_session.sh"
grade() { NO_COLOR=1 "$clothlab" grade --exercises "$work/exercises" --scratch "$work/scratch" "$@"; }
ex01=$work/exercises/01_particles_and_euler.cpp
cp "$source_dir/solutions/01_particles_and_euler.cpp" "$ex01"
cp "$source_dir/solutions/02_spring_dampers.cpp" "$work/exercises/"
sums_before=$(sha256sum "$source_dir"/exercises/*)

echo "== solved: ex01 and ex02 score full marks, the other exercises are not started"
out=$(grade)
echo "$out"
grep -Eq '^ex01\.3 +4 / 4 +4 / 4 +done' <<<"$out" || die "solved ex01.3 is not done"
grep -Eq '^ex02\.1 +6 / 6 +6 / 6 +done' <<<"$out" || die "solved ex02.1 is not done with 6 points"
grep -Eq '^ex03\.1 .*not started' <<<"$out" || die "the stub of ex03.1 is not 'not started'"

echo "== the same file made wrong, and graded with no rebuild asked for"
sed -i 's/return {r + v \* dt, v + a \* dt};/return {r + (v + a * dt) * dt, v + a * dt};/' "$ex01"
grep -q 'return {r + (v + a \* dt) \* dt' "$ex01" || die "the planted mistake is not in $ex01"
out=$(grade --exercise ex01.3)
echo "$out"
grep -Eq '^ex01\.3 +1 / 4 +1 / 4 +failing' <<<"$out" || die "the wrong ex01.3 is not failing 1 / 4"
# The first failing case in full, then one line for each other one, naming the mistake.
grep -q 'got (1.41, 2.5, 3.58), expected (1.4, 2.5, 3.6)' <<<"$out" ||
  die "the first failing case does not show got and expected"
grep -q '^    ex01.3 a particle at rest does not move in its first explicit step: failed: if r changed here you moved the particle with the NEW velocity' <<<"$out" ||
  die "the case that names the mistake has no line of its own"
[[ $(grep -c '^    ex01\.3 .*: failed' <<<"$out") -eq 3 ]] || die "not every failing case has a line"

echo "== the same file broken: ex01 not compiled, with the error; ex02 still graded"
sed -i 's/return m \* g;/return m * g/' "$ex01"
grep -q 'return m \* g$' "$ex01" || die "the planted typo is not in $ex01"
out=$(grade)
echo "$out"
grep -Eq '^ex01\.1 +0 / 2 +0 / 2 +not compiled' <<<"$out" || die "the broken ex01 is not 'not compiled'"
grep -Eq '^ex01\.3 +0 / 4 +0 / 4 +not compiled' <<<"$out" || die "ex01.3 graded a stale binary"
grep -Eq 'exercises/01_particles_and_euler\.cpp:[0-9]+:[0-9]+: error:' <<<"$out" ||
  die "the compiler's error, with its file and line, is not shown"
grep -Eq '^ex02\.1 +6 / 6 +6 / 6 +done' <<<"$out" || die "ex02 was not graded beside the broken ex01"
[[ $(grep -c 'error:' <<<"$out") -eq 1 ]] || die "the error is shown more than once"

echo "== hidden cases: out of the student's grade and list, in with --hidden"
if [[ -d $source_dir/tests/grade-hidden ]]; then
  # (Read whole first: grep -q would end the pipe early.)
  list=$(grade --list)
  grep -q 'hidden:' <<<"$list" && die "--list shows hidden cases without --hidden"
  list=$(grade --list --hidden)
  grep -q 'hidden:' <<<"$list" || die "--list --hidden does not show the hidden cases"
fi

echo "== watch: graded at the start, and again when the file is saved"
log=$work/watch.log
NO_COLOR=1 "$clothlab" watch ex01.1 --exercises "$work/exercises" --scratch "$work/scratch" \
  --rounds 2 >"$log" 2>&1 &
watcher=$!
watch_waits "$log" "$watcher" 120
sed -i 's/return m \* g$/return m * g;/' "$ex01"
watch_ends "$log" "$watcher" 120 "grade again after the file was saved"
grep -Eq '^ex01\.1 +0 / 2 +0 / 2 +not compiled' "$log" || die "watch's first grading is not the broken file's"
grep -q '(01_particles_and_euler.cpp changed)' "$log" || die "watch does not say which file changed"
grep -Eq '^ex01\.1 +2 / 2 +2 / 2 +done' "$log" || die "watch's second grading is not the mended file's"

[[ $sums_before == "$(sha256sum "$source_dir"/exercises/*)" ]] || die "the project's exercises/ changed"
echo "the student's loop grades what is saved"
