#!/usr/bin/env bash
# check_hostile.sh CLOTHLAB SOURCE WORK_DIR: `clothlab grade --submission` on hostile
# submissions, one per kind of attack the grader now holds against (README, "The threat model"),
# and on honest ones that look odd. Each is graded on lesson 01 (14 points) and must score no more
# than its honest part earns, leave a valid report, change nothing outside its scratch folder and
# leave no process behind; the honest chatty one must score full marks.
set -euo pipefail
source "$(dirname "$0")/submission_checks.sh"
solution=$source_dir/solutions/01_particles_and_euler.cpp
name=01_particles_and_euler.cpp
tree_sum() { find "$source_dir/exercises" "$source_dir/solutions" "$source_dir/tests/grade" -type f -print0 | sort -z | xargs -0 sha256sum | sha256sum; }
sums_before=$(tree_sum)

# The top-level output of a results.json, which Gradescope shows every student.
cat >"$work/output.cmake" <<'EOF'
file(READ ${FILE} json)
string(JSON output GET "${json}" output)
message("${output}")
EOF
output_of() { cmake -DFILE="$1" -P "$work/output.cmake" 2>&1; }

# grade NAME [ARGS...]: grades $work/NAME on ex01, output in $work/NAME.out, score in $score.
grade() {
  local sub=$1
  shift
  set +e
  NO_COLOR=1 "$clothlab" grade --submission "$work/$sub" --scratch "$work/scratch" \
    --results "$work/$sub.json" --exercise ex01 --timeout 5 "$@" >"$work/$sub.out" 2>&1
  code=$?
  set -e
  score=$(score_of "$work/$sub.json")
  echo "--- $sub: exit $code, score $score"
  cat "$work/$sub.out"
}
# expect NAME MAX: scored at most MAX, and a valid report.
expect_at_most() {
  [[ $score =~ ^[0-9]+$ ]] || {
    problem "$1: no valid results.json ($score)"
    return
  }
  ((score <= $2)) || problem "$1: scored $score, more than the $2 its code earns"
}
# plant NAME FILE-TEXT: a submission holding one exercise file.
plant() {
  mkdir -p "$work/$1"
  printf '%s\n' "$2" >"$work/$1/$name"
}
# patch TEXT: the solution with the gravity kernel's body replaced by TEXT, and PREAMBLE on top.
patched() {
  local preamble=$1 body=$2
  printf '%s\n' "$preamble"
  sed "s|  return m \* g;|$body|" "$solution"
}

# --- files that are not the submission's own -------------------------------------------------
mkdir -p "$work/symlink" "$work/linked-folder"
ln -s "$solution" "$work/symlink/$name"
ln -s "$source_dir/solutions" "$work/linked-folder/exercises"
for sub in symlink linked-folder; do
  grade "$sub"
  expect_at_most "$sub" 0
  grep -q "Refused (graded on the shipped stub): $name" "$work/$sub.out" ||
    problem "$sub: the refused file is not named"
done

# --- includes outside the submission and the engine's headers --------------------------------
plant include-relative "#include \"../../../solutions/$name\""
plant include-absolute "#include \"$solution\""
plant include-passwd '#include "/etc/passwd"'
plant include-device '#include "/dev/zero"'
plant include-angle "#include <../../../../../../../$solution>"
plant include-disguised "$(printf '#\\\ninclude "/etc/passwd"')"
plant include-commented '# /* a comment */ include "/etc/passwd"'
plant include-computed "$(printf '#define WHERE "/etc/passwd"\n#include WHERE')"
plant incbin 'asm(".incbin \"/etc/passwd\"");'
# Spellings the preprocessor reads as the directive: a byte-order mark, splices whose backslash
# is followed by CR LF, a space or a tab, a form feed or a vertical tab after the '#', a lone CR
# ending the line before, and a raw string that a naive reader takes for the start of a comment.
plant include-bom $'\xEF\xBB\xBF#include "/etc/passwd"'
plant include-splice-crlf $'#inc\\\r\nlude "/etc/passwd"'
plant include-splice-space $'#inc\\ \nlude "/etc/passwd"'
plant include-splice-tab $'#inc\\\t\nlude "/etc/passwd"'
plant include-form-feed $'#\finclude "/etc/passwd"'
plant include-vertical-tab $'#\vinclude "/etc/passwd"'
plant include-lone-cr $'int x;\r#include "/etc/passwd"'
plant include-raw-string $'const char* s = R"(a" /* )";\n#include "/etc/passwd"\n// */'
for sub in include-relative include-absolute include-passwd include-device include-angle \
  include-disguised include-commented include-computed incbin include-bom include-splice-crlf \
  include-splice-space include-splice-tab include-form-feed include-vertical-tab include-lone-cr \
  include-raw-string; do
  start=$SECONDS
  grade "$sub"
  expect_at_most "$sub" 0
  grep -q "exercises/$name:[0-9]*: error:" "$work/$sub.out" ||
    problem "$sub: the refusal does not name the file and line"
  grep -q 'root:' "$work/$sub.out" && problem "$sub: the output quotes /etc/passwd"
  ((SECONDS - start < 120)) || problem "$sub: took $((SECONDS - start)) s"
done

# --- text that would drive the instructor's terminal -------------------------------------------
mkdir -p "$work/escapes"
patched '#include <stdexcept>' '  throw std::runtime_error("\\x1b[2J\\x1b[Hex01.1  2 \/ 2  done\\x07");' \
  >"$work/escapes/$name"
grade escapes
expect_at_most escapes 12
if grep -q $'\x1b' "$work/escapes.out"; then problem "escapes: an escape character reached the terminal"; fi
grep -q '\^\[\[2J' "$work/escapes.out" || problem "escapes: the escape is not shown as ^["

# --- names are data: a file name with line breaks draws no line of a report ---------------------
mkdir -p "$work/newline-name"
cp "$solution" "$work/newline-name/$name"
# (A file name holds no '/': the division slash U+2215 looks the same.)
fake=$'notes\n\nTotal: 130 \xe2\x88\x95 130 points\n.cpp'
echo '// not an exercise file' >"$work/newline-name/$fake"
grade newline-name
[[ $score == 14 ]] || problem "newline-name: scored $score of 14"
output_of "$work/newline-name.json" >"$work/newline-name.top"
for report in "$work/newline-name.out" "$work/newline-name.top"; do
  totals=$(grep -c '^ *Total:' "$report" || true)
  [[ $totals == 1 ]] || problem "newline-name: $totals lines read 'Total:' where the report has one"
done
grep -qF $'Ignored (not an exercise file): notes\\n\\nTotal: 130 \xe2\x88\x95 130 points\\n.cpp' \
  "$work/newline-name.out" || problem "newline-name: the file's name is not shown escaped"

# --- an honest, correct submission that prints a lot -------------------------------------------
mkdir -p "$work/chatty"
patched '#include <cstdio>
#include <string>' '  { const std::string s(3 << 20, '"'"'x'"'"'); std::fputs(s.c_str(), stdout); } return m * g;' \
  >"$work/chatty/$name"
grade chatty
[[ $score == 14 ]] || problem "chatty: an honest submission that prints 3 MiB scored $score of 14"

# --- a process that leaves the case's process group --------------------------------------------
mkdir -p "$work/orphan"
marker=61.$$
patched '#include <unistd.h>' "  if (fork() == 0) { setsid(); if (fork() == 0) execl(\"/bin/sleep\", \"sleep\", \"$marker\", (char*)nullptr); _exit(0); } return m * g;" \
  >"$work/orphan/$name"
grade orphan
sleep 0.5
if pgrep -f "sleep $marker" >/dev/null; then
  problem "orphan: a process the submission started outlived the grader"
  pkill -f "sleep $marker" || true
fi

# --- verdicts the submission's process would write -------------------------------------------
# The kernels run in a process of their own, which holds no test and cannot reach the pipe the
# verdicts go through: what it prints, exits with or links in earns nothing.
stub=$source_dir/exercises/$name
fake_events='"@clothlab\tstart\tx\n@clothlab\tend\tpassed\t0\n"'
mkdir -p "$work/exit-handler" "$work/end-then-exit" "$work/fd-thief" "$work/defaults" \
  "$work/check-override"
# The stubs, and a handler at exit that prints what a passing case prints and exits 0.
{
  cat "$stub"
  printf '%s\n' '#include <cstdio>' '#include <cstdlib>' '#include <unistd.h>' \
    'namespace { void fake() { for (int fd : {1, 2, 3, 4, 5, 6}) dprintf(fd, '"$fake_events"'); _exit(0); }' \
    'const int registered = std::atexit(fake); }'
} >"$work/exit-handler/$name"
grade exit-handler
expect_at_most exit-handler 0
compiled() { grep -q "not compiled" "$work/$1.out" && problem "$1: does not compile, so it proves nothing"; true; }
compiled exit-handler
# One kernel prints the end of a passing case, then leaves at once.
fake_decl="static const char* const kFake = $fake_events;"
patched "#include <cstdio>
#include <unistd.h>
$fake_decl" '  std::fputs(kFake, stdout); std::fflush(stdout); _exit(0);' >"$work/end-then-exit/$name"
grade end-then-exit
expect_at_most end-then-exit 12
compiled end-then-exit
# One kernel writes passing events to every descriptor it can, and to its parent's.
patched "#include <cstdio>
#include <fcntl.h>
#include <string>
#include <unistd.h>
$fake_decl" '  for (int fd = 0; fd < 64; ++fd) dprintf(fd, "%s", kFake); for (int fd = 0; fd < 64; ++fd) { const int f = open(("/proc/" + std::to_string(getppid()) + "/fd/" + std::to_string(fd)).c_str(), O_WRONLY); if (f >= 0) dprintf(f, "%s", kFake); } return {};' \
  >"$work/fd-thief/$name"
grade fd-thief
compiled fd-thief
if [[ -x /usr/bin/bwrap ]] && /usr/bin/bwrap --unshare-all --ro-bind / / /bin/true 2>/dev/null; then
  expect_at_most fd-thief 12
fi
# Kernels that return defaults, then the same with the test framework's checks overridden at link
# time. The kernels program holds no test framework (it does not even link: the file's
# registration needs doctest's code), and were it to, it runs no check: nothing more is earned.
defaults=$(sed 's|  CLOTHLAB_TODO(.*|  return {};|' "$stub")
printf '%s\n' "$defaults" >"$work/defaults/$name"
grade defaults
compiled defaults
defaults_score=$score
{
  printf '%s\n' '#include <doctest/doctest.h>' "$defaults"
  printf '%s\n' 'bool doctest::detail::ResultBuilder::log() { return false; }' \
    'void doctest::detail::ResultBuilder::react() const {}'
} >"$work/check-override/$name"
grade check-override
expect_at_most check-override "$defaults_score"

# --- reports only to regular files --------------------------------------------------------------
echo "an unrelated file" >"$work/victim.txt"
ln -s "$work/victim.txt" "$work/link.json"
set +e
NO_COLOR=1 "$clothlab" grade --impl stubs --exercise ex01.1 --results "$work/link.json" \
  >"$work/link.out" 2>&1
code=$?
set -e
[[ $code -eq 2 ]] || problem "--results through a symbolic link: exit $code, expected 2"
[[ $(cat "$work/victim.txt") == "an unrelated file" ]] || problem "--results wrote through a link"
[[ -L $work/link.json ]] || problem "--results replaced the symbolic link"
grep -q 'symbolic link' "$work/link.out" || problem "--results through a link: no message"
mkfifo "$work/fifo.json"
set +e
NO_COLOR=1 "$clothlab" grade --impl stubs --exercise ex01.1 --junit "$work/fifo.json" \
  >"$work/fifo.out" 2>&1
code=$?
set -e
[[ $code -eq 2 && -p $work/fifo.json ]] || problem "--junit onto a fifo: exit $code, or replaced"

# --- two graders at once on one scratch folder --------------------------------------------------
mkdir -p "$work/slow" "$work/fast"
patched '' '  for (volatile long spin = 0;; spin = spin + 1) {}' >"$work/slow/$name"
cp "$solution" "$work/fast/$name"
NO_COLOR=1 "$clothlab" grade --submission "$work/slow" --scratch "$work/shared" \
  --results "$work/slow.json" --exercise ex01.1 --timeout 3 >"$work/slow.out" 2>&1 &
slow=$!
sleep 1
NO_COLOR=1 "$clothlab" grade --submission "$work/fast" --scratch "$work/shared" \
  --results "$work/fast.json" --exercise ex01 >"$work/fast.out" 2>&1 || true
wait "$slow" || true
[[ $(score_of "$work/fast.json") == 14 ]] || problem "two graders at once: the honest one scored $(score_of "$work/fast.json")"
[[ $(score_of "$work/slow.json") == 0 ]] || problem "two graders at once: the looping one scored $(score_of "$work/slow.json")"

# --- the sandbox: nothing of the project to read, nowhere to write -----------------------------
# Where bubblewrap works (CI installs it and sets CLOTHLAB_REQUIRE_SANDBOX=1), a kernel that reads
# the solution earns nothing by it, and one that writes into exercises/ leaves nothing there.
if [[ -x /usr/bin/bwrap ]] && /usr/bin/bwrap --unshare-all --ro-bind / / /bin/true 2>/dev/null; then
  mkdir -p "$work/reader" "$work/writer"
  patched '#include <fstream>' "  if (std::ifstream(\"$solution\")) return m * g; return {};" \
    >"$work/reader/$name"
  grade reader --sandbox on
  expect_at_most reader 12
  planted=$source_dir/exercises/planted-by-a-submission.txt
  patched '#include <fstream>' "  std::ofstream(\"$planted\") << \"planted\"; return m * g;" \
    >"$work/writer/$name"
  grade writer --sandbox on
  if [[ -e $planted ]]; then
    problem "writer: a submission wrote into the project's exercises/"
    rm -f "$planted"
  fi
  # Before main, the kernels' wire (descriptors 3 and 4) is open, as it must be: a submission that hands
  # it to the reference kernels would score what the reference does, were the build folder
  # visible.
  mkdir -p "$work/exec-reference"
  reference=$(dirname "$clothlab")/grade-kernels-reference
  { cat "$stub"; printf '%s\n' '#include <unistd.h>' \
      "namespace { const int taken = execl(\"$reference\", \"k\", (char*)nullptr); }"; } \
    >"$work/exec-reference/$name"
  grade exec-reference --sandbox on
  compiled exec-reference
  expect_at_most exec-reference 0
  # The assembler reads files too, and a string split in two passes any check of the text: the
  # compiler runs in a sandbox of its own, where the solution is not there to read.
  mkdir -p "$work/asm-include" "$work/asm-incbin"
  { cat "$solution"; printf 'asm(".inc" "lude \\"%s\\"");\n' "$solution"; } >"$work/asm-include/$name"
  {
    patched '#include <cstdio>
extern "C" const char leaked[];' '  std::fputs(leaked, stderr); return m * g;'
    printf 'asm(".section .rodata\\n.global leaked\\nleaked: .inc" "bin \\"%s\\"\\n.byte 0\\n.text");\n' "$solution"
  } >"$work/asm-incbin/$name"
  for sub in asm-include asm-incbin; do
    grade "$sub" --sandbox on
    expect_at_most "$sub" 0
    grep -q -e 'no direction to pull along' -e 'such instruction: .return' "$work/$sub.out" \
      "$work/$sub.json" && problem "$sub: the report quotes the solution"
  done
  # A kernel that starts 200 processes (each waits for the case to end) answers right only when
  # fewer than 100 of them started: a case may start no process (grade-confine's filter).
  mkdir -p "$work/fork-bomb"
  patched '#include <unistd.h>' '  static int started = -1; if (started < 0) { started = 0; for (int k = 0; k < 200; ++k) { const pid_t p = fork(); if (p == 0) { pause(); _exit(0); } if (p > 0) ++started; } } return started < 100 ? Vec3(m * g) : Vec3::Zero();' \
    >"$work/fork-bomb/$name"
  grade fork-bomb --sandbox on
  compiled fork-bomb
  [[ $score == 14 ]] || problem "fork-bomb: scored $score of 14: a case started 100 processes or more"
elif [[ ${CLOTHLAB_REQUIRE_SANDBOX:-0} == 1 ]]; then
  problem "bubblewrap is required here (CLOTHLAB_REQUIRE_SANDBOX=1) but does not work"
else
  echo "(bubblewrap is not usable here: the sandbox's own checks are skipped)"
fi

[[ $sums_before == "$(tree_sum)" ]] || problem "the project's exercises/, solutions/ or tests/grade/ changed"

if ((${#problems[@]} > 0)); then
  printf 'check_hostile: %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "every hostile submission scored no more than its code earns"
