#!/usr/bin/env bash
# check_planted_hints.sh SOURCE WORK_DIR: check_planted.sh refuses a planted mistake whose report
# no "?" line reads, unless a "! no hint check: WHY" line gives the reason, and the project's
# planted/mutants.txt passes that rule. Nothing is graded (check_planted.sh --parse-only): 2.4 s
# at a load of 8 on two cores.
set -euo pipefail
harness=$(cd "$(dirname "$0")" && pwd)
source_dir=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
problems=()

# expect NAME STATUS PATTERN...: check_planted.sh --parse-only on $work/NAME.txt (or on the file
# NAME, given with its path) exits with STATUS and prints a line matching each PATTERN.
expect() {
  local plants=$1 status=$2 pattern out code
  shift 2
  [[ $plants == */* ]] || plants=$work/$plants.txt
  out=$(bash "$harness/check_planted.sh" /nonexistent-clothlab "$source_dir" "$work/parse" \
    "$plants" --parse-only 2>&1) && code=0 || code=$?
  echo "== $(basename "$plants"): exit $code"
  echo "$out"
  [[ $code -eq $status ]] ||
    problems+=("$(basename "$plants"): check_planted.sh exited with $code, expected $status")
  for pattern in "$@"; do
    grep -Eq -- "$pattern" <<<"$out" ||
      problems+=("$(basename "$plants"): no line of check_planted.sh's output matches \"$pattern\"")
  done
}

# One planted mistake of ex01.1 (g / m for m g), with what follows it in each file.
plant() {
  printf '# a planted mistake\n\nmutant ex01.1 01_particles_and_euler.cpp: g divided by the mass\n'
  printf -- '- return m * g;\n+ return g / m;\n'
}
{ plant; } >"$work/no-hint.txt"
{ plant; printf '? your answer is what g divided by the mass\n'; } >"$work/hinted.txt"
{ plant; printf '! no hint check: no case can tell g / m from m g\n'; } >"$work/excused.txt"
{ plant; printf '! no hint check:   \n'; } >"$work/no-reason.txt"
{ plant; printf '? g / m\n! no hint check: both\n'; } >"$work/both.txt"

expect no-hint 1 'no-hint\.txt:3: mutant ex01\.1 \(g divided by the mass\): no "\?" line checks' \
  'nothing graded'
expect hinted 0 'reads well: 1 mutants'
expect excused 0 'reads well: 1 mutants'
expect no-reason 1 'no-reason\.txt:3: .*gives no reason'
expect both 1 'both\.txt:3: .*keep one'
# The project's own: every planted mistake checks its hint (or says why not).
expect "$source_dir/tests/grade/harness/planted/mutants.txt" 0 'reads well'
expect "$source_dir/tests/grade/harness/planted/trivial.txt" 0 'reads well'

if [[ ${#problems[@]} -gt 0 ]]; then
  printf 'check_planted_hints: %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "check_planted_hints: a planted mistake without its hint check is refused, and none is"
