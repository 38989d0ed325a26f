#!/usr/bin/env bash
# check_interrupt.sh CLOTHLAB CASES WORK_DIR: a grader stopped by TERM (an autograder's time
# limit, or Ctrl-C's INT) while a case hangs kills that case, exits 130 and leaves valid results
# for the cases it ran.
set -u
clothlab=$1 cases=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
results=$work/results.json
fail() {
  echo "check_interrupt: $*" >&2
  cat "$work/out.txt" >&2
  exit 1
}

# A copy of the binary, so that the check for leftover processes sees only this grader's.
cp "$cases" "$work/interrupted-cases"
cases=$work/interrupted-cases
NO_COLOR=1 "$clothlab" grade --binary "$cases" --timeout 300 --results "$results" \
  >"$work/out.txt" 2>&1 &
pid=$!
# Results are rewritten after every case: once ex90.4 (the fourth) is in them, the fifth, which
# hangs, is running.
for _ in $(seq 600); do
  grep -q 'crashed: SIGABRT' "$results" 2>/dev/null && break
  sleep 0.1
done
grep -q 'crashed: SIGABRT' "$results" || fail "ex90.4 never finished"
sleep 0.5
kill -TERM "$pid"
start=$SECONDS
wait "$pid"
code=$?
[[ $code -eq 130 ]] || fail "the grader exited with $code after TERM, expected 130"
((SECONDS - start < 20)) || fail "the grader took $((SECONDS - start)) s to stop"
grep -q 'interrupted: the results of the cases run so far are written' "$work/out.txt" ||
  fail "the grader did not say it was interrupted"
pgrep -f "$cases" >/dev/null && fail "a test process outlived the grader"
# ex90.1 passed (2 points) before the hang; nothing after it ran.
grep -q '^  "score": 2,' "$results" || fail "results.json does not give the 2 points of ex90.1"
grep -q 'not run (interrupted)' "$results" || fail "the hanging case is not marked interrupted"
# The status and output of ex91.1, read by CMake's JSON parser.
cat >"$work/case.cmake" <<'EOF'
file(READ ${FILE} json)
string(JSON count LENGTH "${json}" tests)
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${json}" tests ${i} name)
  if(name STREQUAL "ex91.1 passes after the crashes")
    string(JSON status GET "${json}" tests ${i} status)
    string(JSON output GET "${json}" tests ${i} output)
    message("${status}: ${output}")
  endif()
endforeach()
EOF
[[ $(cmake -DFILE="$results" -P "$work/case.cmake" 2>&1) == "failed: not run"* ]] ||
  fail "ex91.1, after the hang, is not marked as not run"
echo "interrupted after ex90.4: exit 130, results for the cases run, no process left"
