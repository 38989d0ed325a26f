#!/usr/bin/env bash
# check_wire.sh CLOTHLAB SOURCE WORK_DIR: `clothlab grade --submission` on kernels that abuse the
# wire between the grading binary and the kernels' process (kernel_wire.hpp), and on an honest
# submission that prints before main.
#
# Each hostile submission is the reference solution with one kernel's body replaced. A kernel
# that calls its AccelerationField with matrices of another shape than the call's state, or
# returns its changeable arguments in another shape, must fail each of its cases as a break of
# the protocol, before the test's field or the test runs on them (neither reads or writes past
# the end of what it holds): the grading binary never crashes, and the other exercise of the file
# keeps its points. A kernel returning an index out of range fails its cases with the kernel and
# the value named.
set -euo pipefail
source "$(dirname "$0")/submission_checks.sh"

# points FILE PREFIX: the points earned, and the points there are, by the cases whose name starts
# with PREFIX, in a results.json (which must be valid JSON).
points() {
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import json, sys
tests = [t for t in json.load(open(sys.argv[1]))["tests"] if t["name"].startswith(sys.argv[2])]
print(f'{sum(t["score"] for t in tests):g} {sum(t["max_score"] for t in tests):g} {len(tests)}')
EOF
}

# grade NAME EXERCISE: grades $work/NAME on EXERCISE, output in $work/NAME.out.
grade() {
  set +e
  NO_COLOR=1 "$clothlab" grade --submission "$work/$1" --scratch "$work/scratch" \
    --results "$work/$1.json" --exercise "$2" --timeout 20 >"$work/$1.out" 2>&1
  set -e
  echo "--- $1"
  cat "$work/$1.out"
}

# replaced FILE EXERCISE[@N] BODY: the solution FILE with the region of EXERCISE (BEGIN to END,
# its Nth, 1 unless told) replaced by BODY.
replaced() {
  [[ -n ${preamble:-} ]] && printf '%s\n' "$preamble"
  local exercise=${2%@*} nth=1
  [[ $2 == *@* ]] && nth=${2#*@}
  awk -v ex="$exercise" -v nth="$nth" -v body="$3" '
    $0 ~ "// BEGIN " ex ":" && ++seen == nth { print body; skipping = 1; next }
    skipping && $0 ~ "// END " ex { skipping = 0; next }
    !skipping { print }' "$source_dir/solutions/$1"
}

# hostile NAME FILE EXERCISE[@N] OTHER MESSAGE BODY: a submission whose kernel in the region of
# EXERCISE is BODY must score 0 on EXERCISE (less than its full points with @N: the exercise
# has other kernels), its cases failing with MESSAGE, no case reported as a crash of the grading
# binary, and full points on OTHER (the file's other exercise).
hostile() {
  local name=$1 file=$2 region=$3 other=$4 message=$5 body=$6
  local exercise=${region%@*}
  mkdir -p "$work/$name"
  replaced "$file" "$region" "$body" >"$work/$name/$file"
  grade "$name" "${exercise%.*}"
  local got
  got=$(points "$work/$name.json" "$exercise") || {
    problem "$name: no valid results.json"
    return
  }
  read -r earned total cases <<<"$got"
  if [[ $region == *@* ]]; then
    [[ $cases -gt 0 && $earned != "$total" ]] || problem "$name: $exercise scored $earned of $total"
  else
    [[ $cases -gt 0 && $earned == 0 ]] || problem "$name: $exercise scored $earned of $total"
  fi
  local said
  said=$(grep -c -F -- "$message" "$work/$name.out" || true)
  ((said >= 1)) || problem "$name: the report does not say \"$message\""
  if grep -q -e 'SIGSEGV' -e 'SIGABRT' -e 'SIGBUS' -e 'malloc()' -e 'free()' "$work/$name.out"; then
    problem "$name: the grading binary crashed"
  fi
  if [[ -n $other ]]; then
    read -r earned total cases <<<"$(points "$work/$name.json" "$other")"
    [[ $earned == "$total" ]] || problem "$name: $other (untouched) scored $earned of $total"
  fi
}

broke="broke the kernels' protocol (a matrix of 3 x"
integrators=07_integrators.cpp
# The field called with a state of more particles than the call's, of none, of two million.
hostile callback-wide $integrators ex07.1 ex07.2 "$broke 1003 where the call's is 3 x" '
  Matrix3X xs = Matrix3X::Zero(3, x.cols() + 1000), vs = xs, as = xs;
  accel(xs, vs, as);
  (void)dt, (void)stages;'
hostile callback-empty $integrators ex07.1 ex07.2 "$broke 0 where the call's is 3 x" '
  Matrix3X none(3, 0), as(3, 0);
  accel(none, none, as);
  (void)dt, (void)stages, (void)v;'
hostile callback-huge $integrators ex07.1 ex07.2 "$broke 2000000 where the call's is 3 x" '
  Matrix3X big = Matrix3X::Zero(3, 2000000), as = big;
  accel(big, big, as);
  (void)dt, (void)stages, (void)x, (void)v;'
# The field called with the right state, while the caller's x (sent along, as it is now) has
# grown.
hostile callback-outs $integrators ex07.1 ex07.2 "$broke 53 where the call's is 3 x" '
  x.conservativeResize(3, x.cols() + 50);
  accel(stages.x[0], stages.v[0], stages.a[0]);
  (void)dt, (void)v;'
# A right step whose x comes back with no columns (the grading binary once segfaulted on it), and
# one whose stages come back wider.
hostile return-empty $integrators ex07.1 ex07.2 "$broke 0 where the call's is 3 x" '
  Matrix3X &a1 = stages.a[0], &x2 = stages.x[1], &v2 = stages.v[1], &a2 = stages.a[1];
  accel(x, v, a1);
  x2 = x + 0.5 * dt * v;
  v2 = v + 0.5 * dt * a1;
  accel(x2, v2, a2);
  x.resize(3, 0);
  v += dt * a2;'
hostile return-wide-stages $integrators ex07.2 ex07.1 "in its answer) during a call of rk4_step" '
  accel(stages.x[0], stages.v[0], stages.a[0]);
  for (Matrix3X& m : stages.a)
    m = Matrix3X::Zero(3, x.cols() + 100);
  (void)dt, (void)v;'

# Indices out of range, which the caller would index with.
hostile hash-slot 10_collision_detection.cpp ex10.1@2 ex10.2 "cell_hash returned the slot" '
  (void)c;
  return table_size;'
hostile tears-index 06_plasticity_and_tearing.cpp ex06.2 ex06.1 "select_tears returned the spring index" '
  (void)ends, (void)tear_strain, (void)max_tears;
  return {strain.size() + 7};'

# Messages forged on the wire. An answer of bending_pairs whose count claims a pair for every
# byte of its 64 MiB: read as it claims, it would have the grading binary allocate 1 GiB; the
# count is checked against the 16 bytes a pair takes before anything is allocated.
preamble='#include <unistd.h>
#include <cstdint>
#include <cstring>
#include <vector>'
hostile forged-count 04_bending_springs.cpp ex04.1 "" "(a message holds fewer values than it says in its answer)" '
  static std::vector<char> payload(std::size_t{64} << 20);
  const std::uint64_t count = payload.size() - 8;
  std::memcpy(payload.data(), &count, sizeof count);
  const std::uint32_t kind_kernel[2] = {2, 8};  // Return, bending_pairs
  const std::uint64_t size = payload.size();
  if (write(4, kind_kernel, sizeof kind_kernel) < 0 || write(4, &size, sizeof size) < 0) _exit(1);
  for (std::size_t at = 0; at < payload.size();) {
    const ssize_t n = write(4, payload.data() + at, payload.size() - at);
    if (n <= 0) break;
    at += static_cast<std::size_t>(n);
  }
  _exit(0);
  (void)rows, (void)cols;'
# A forged exception, with eight bytes after its values: every message is read to its end.
hostile forged-throw 08_stability.cpp ex08.1 "" "(a message holds more values than its kernel takes in what it threw)" '
  const char text[] = "an exception with bytes after it";
  std::vector<char> bytes;
  const auto add = [&bytes](const void* p, std::size_t n) {
    bytes.insert(bytes.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n);
  };
  const std::uint32_t thrown = 2;  // Thrown::Exception
  const std::uint64_t a = sizeof text - 1, b = 0, extra = 0;
  add(&thrown, sizeof thrown);
  add(&a, sizeof a);
  add(text, a);
  add(&b, sizeof b);
  add(&extra, sizeof extra);
  const std::uint32_t kind_kernel[2] = {3, 14};  // Throw, largest_stable_dt_explicit_euler
  const std::uint64_t size = bytes.size();
  if (write(4, kind_kernel, sizeof kind_kernel) < 0 || write(4, &size, sizeof size) < 0 ||
      write(4, bytes.data(), bytes.size()) < 0)
    _exit(1);
  _exit(0);
  (void)k, (void)m, (void)c;'
preamble=

# --- an honest submission that prints 2 MiB before main -----------------------------------------
# A static object's constructor runs before main, before the kernels' process could move its
# wire anywhere: the wire must not be its standard output.
mkdir -p "$work/chatty-before-main"
{
  printf '%s\n' '#include <cstdio>' '#include <string>'
  cat "$source_dir/solutions/01_particles_and_euler.cpp"
  printf '%s\n' 'namespace {' 'struct Greeting {' \
    '  Greeting() {' \
    '    const std::string line(1023, '"'"'x'"'"');' \
    '    for (int k = 0; k < 2048; ++k) std::printf("%s\n", line.c_str());' \
    '    std::fprintf(stderr, "a word on the standard error too\n");' \
    '  }' '} greeting;' '}  // namespace'
} >"$work/chatty-before-main/01_particles_and_euler.cpp"
grade chatty-before-main ex01
read -r earned total cases <<<"$(points "$work/chatty-before-main.json" ex01)"
[[ $cases -gt 0 && $earned == "$total" ]] ||
  problem "chatty-before-main: an honest submission that prints 2 MiB before main scored $earned of $total"

if ((${#problems[@]} > 0)); then
  printf 'check_wire: %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "every kernel that abused the wire failed its cases cleanly; the honest one kept its points"
