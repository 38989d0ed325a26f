#!/usr/bin/env bash
# check_confinement.sh CLOTHLAB SOURCE WORK_DIR: what bounds a submission as a whole, graded with
# `clothlab grade --submission` on lesson 01 (14 points, 2 of them on the gravity kernel):
# - its environment is PATH, LANG and HOME alone, in every mode, and so is its compiler's;
# - a case is one process with threads (a pool of 300 keeps its points), its memory is bounded as a
#   whole (no child processes to hold more) and so are its files in memory (/tmp, /dev/shm);
# - its build writes no file over the limit and leaves nothing in the scratch folder;
# and, as root without a sandbox (bubblewrap hidden from the grader), on a copy of the build:
# - nothing the submission's code does in the scratch folder reaches the next submission, or makes
#   the grader write where it points;
# - what holds the hidden tests cannot be read by the user the code runs as;
# - `--sandbox off` refuses to run the code as root unless told twice, and then warns.
# Each hostile kernel answers right only when the bound held, so it scores 14 exactly then.
set -euo pipefail
source "$(dirname "$0")/submission_checks.sh"
name=01_particles_and_euler.cpp
solution=$source_dir/solutions/$name

# grade NAME [ARGS...]: grades $work/NAME on ex01 with $grader (the one under test, or the copy's);
# output in $work/NAME.out, score in $score, exit status in $code.
grader=$clothlab
run=()
grade() {
  local sub=$1
  shift
  rm -f "$work/$sub.json"
  set +e
  NO_COLOR=1 "${run[@]}" "$grader" grade --submission "$work/$sub" --scratch "$work/scratch" \
    --results "$work/$sub.json" --exercise ex01 --timeout 10 "$@" >"$work/$sub.out" 2>&1
  code=$?
  set -e
  score=$(score_of "$work/$sub.json" || true)
  echo "--- $sub: exit $code, score $score"
  cat "$work/$sub.out"
}
expect_full() {
  [[ $score == 14 ]] || problem "$1: scored $score of 14 ($2)"
}
# patched NAME PREAMBLE CONDITION: the solution, with PREAMBLE on top, whose gravity kernel answers
# right only while CONDITION holds.
patched() {
  mkdir -p "$work/$1"
  {
    printf '%s\n' "$2"
    sed "s|  return m \* g;|  if (!($3)) return Vec3::Zero(); return m * g;|" "$solution"
  } >"$work/$1/$name"
}
scratch_mib() { du -sm "$work/scratch" | cut -f1; }

# --- the environment --------------------------------------------------------------------------
patched environment '#include <cstring>
#include <unistd.h>
// True when the environment holds PATH, LANG and HOME, and nothing else (but ASAN_OPTIONS
// in a sanitized build).
static bool only_three() {
  int count = 0;
  for (char** e = environ; *e != nullptr; ++e, ++count) {
#if defined(__SANITIZE_ADDRESS__)
    if (std::strncmp(*e, "ASAN_OPTIONS=", 13) == 0) { --count; continue; }
#endif
    if (std::strncmp(*e, "PATH=", 5) != 0 && std::strncmp(*e, "LANG=", 5) != 0 &&
        std::strncmp(*e, "HOME=", 5) != 0)
      return false;
  }
  return count == 3;
}' 'only_three()'
CLOTHLAB_GRADER_SECRET=leaked grade environment
expect_full environment "the grader's environment reached the kernels"

# --- a pool of threads is honest --------------------------------------------------------------
patched threads '#include <thread>
#include <vector>
// Starts 300 threads, each adding one, and joins them: true when all ran.
static bool pool_ran() {
  static int ran = -1;
  if (ran < 0) {
    std::vector<std::thread> pool;
    std::vector<int> done(300, 0);
    for (int k = 0; k < 300; ++k) pool.emplace_back([&done, k] { done[k] = 1; });
    for (std::thread& t : pool) t.join();
    ran = 0;
    for (int d : done) ran += d;
  }
  return ran == 300;
}' 'pool_ran()'

# --- no child process to hold more memory -----------------------------------------------------
# Address space is reserved (not touched): what a case could fill. Three children and the case
# itself each reserve 3 GiB; together they may not reach the 4 GiB one process is allowed.
patched children '#include <sys/mman.h>
#include <unistd.h>
// The GiB of address space this case and three children reserved at once.
static int reserved_gib() {
  static int total = -1;
  if (total >= 0) return total;
  const size_t size = size_t{3} << 30;
  total = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE,
               -1, 0) != MAP_FAILED ? 3 : 0;
  int fds[2];
  if (pipe(fds) != 0) return total;
  for (int k = 0; k < 3; ++k) {
    if (fork() != 0) continue;
    const bool got = mmap(nullptr, size, PROT_READ | PROT_WRITE,
                          MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0) != MAP_FAILED;
    if (write(fds[1], got ? "3" : "0", 1) != 1) _exit(1);
    pause();
  }
  close(fds[1]);
  for (char c; read(fds[0], &c, 1) == 1;) total += c - 0x30;
  return total;
}' 'reserved_gib() < 4'
sed -i 's|for (char c; read|usleep(500000); for (char c; read|' "$work/children/$name"

# --- files in memory ----------------------------------------------------------------------------
patched memory-files '#include <csignal>
#include <fcntl.h>
#include <string>
#include <sys/mman.h>
#include <unistd.h>
// Writes files of 32 MiB (under the 64 MiB a case may write in one) in /tmp and /dev/shm, and
// into memory files, until 512 MiB or a refusal: the MiB that were written.
static long held_mib() {
  static long total = -1;
  if (total >= 0) return total;
  std::signal(SIGXFSZ, SIG_IGN);
  total = 0;
  const std::string block(1 << 20, 0x78);
  for (int k = 0; k < 16; ++k) {
    const std::string path = (k % 2 ? "/tmp" : "/dev/shm") + std::string("/clothlab-held-") +
                             std::to_string(k);
    int fd = k < 12 ? open(path.c_str(), O_WRONLY | O_CREAT, 0600)
                    : static_cast<int>(memfd_create("f", 0));
    if (fd < 0) continue;
    for (int mib = 0; mib < 32; ++mib, ++total)
      if (write(fd, block.data(), block.size()) != static_cast<long>(block.size())) break;
    if (k < 12) close(fd);  // a memory file is gone once closed
  }
  return total;
}' 'held_mib() <= 160'

# Graded in the sandbox here, and without it as root below.
bounded() {
  grade threads "$@"
  expect_full threads "a correct solution with a pool of 300 threads lost points"
  grade children "$@"
  expect_full children "a case and its children held more than one process's 4 GiB"
  grade memory-files "$@"
  expect_full memory-files "a case held more than 160 MiB in files in memory"
  rm -f /tmp/clothlab-held-* /dev/shm/clothlab-held-* 2>/dev/null || true
}
if [[ -x /usr/bin/bwrap ]] && /usr/bin/bwrap --unshare-all --ro-bind / / /bin/true 2>/dev/null; then
  bounded --sandbox on
elif [[ ${CLOTHLAB_REQUIRE_SANDBOX:-0} == 1 ]]; then
  problem "bubblewrap is required here (CLOTHLAB_REQUIRE_SANDBOX=1) but does not work"
else
  echo "(bubblewrap is not usable here: the sandbox's bounds are not checked)"
fi

# --- the build's outputs --------------------------------------------------------------------------
# 200 MiB of initialised data: an object file of 200 MiB, over the limit on any file of the build.
mkdir -p "$work/large-object"
{ cat "$solution"; echo 'char clothlab_ballast[200 << 20] = {1};'; } >"$work/large-object/$name"
grade large-object
[[ $score == 0 ]] || problem "large-object: an object file of 200 MiB was built (score $score)"
grep -q 'larger than 64 MiB' "$work/large-object.out" ||
  problem "large-object: the report does not say that a file of the build was too large"
(($(scratch_mib) < 8)) ||
  problem "large-object: $(scratch_mib) MiB left in the scratch folder"
mkdir -p "$work/honest"
cp "$solution" "$work/honest/$name"
grade honest
expect_full honest "the reference solution"
(($(scratch_mib) < 8)) || problem "honest: $(scratch_mib) MiB left in the scratch folder"

# --- as root, without a sandbox -------------------------------------------------------------------
if [[ $(id -u) != 0 ]]; then
  echo "(not root: the modes without a sandbox, where the submission runs as nobody, are not checked)"
elif ! command -v unshare >/dev/null || ! unshare --mount true 2>/dev/null; then
  echo "(no mount namespace here to hide bubblewrap in: the modes without a sandbox are not checked)"
else
  # A copy of what grades (the kit's inputs stay where they are, read-only): no grading here can
  # touch the real build.
  build=$(dirname "$clothlab")
  copy=$work/copy
  mkdir -p "$copy/tests/grade/CMakeFiles"
  for program in clothlab grade-cases grade-confine grade-kit; do
    [[ ! -e $build/$program ]] || cp -a "$build/$program" "$copy/"
  done
  cp -a "$build/tests/grade/CMakeFiles/clothlab_grade_tests.dir" "$copy/tests/grade/CMakeFiles/"
  grader=$copy/clothlab
  # No bubblewrap: the path the grader looks for it at holds a program that fails.
  run=(unshare --mount sh -c 'mount --bind /bin/false /usr/bin/bwrap && exec "$@"' sh)
  nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
  sum() { sha256sum "$copy/grade-cases" | cut -d' ' -f1; }
  before=$(sum)
  scratch=$work/scratch

  grade environment
  expect_full environment "without a sandbox, the grader's environment reached the kernels"
  grep -q 'WARNING: no sandbox' "$work/environment.out" || problem "no sandbox: no warning"
  bounded
  # Nor does it reach the compiler: a CPATH set for the grader would find the solution by a
  # header's name the include filter lets pass.
  mkdir -p "$work/cpath"
  echo "#include <$name>" >"$work/cpath/$name"
  CPATH=$source_dir/solutions grade cpath
  [[ $score == 0 ]] || problem "cpath: the grader's CPATH reached the compiler (score $score)"

  # A link planted where the next grading writes an exercise file.
  patched planter "#include <unistd.h>
static bool plant() {
  unlink(\"$scratch/exercises/$name\");
  return symlink(\"$copy/grade-cases\", \"$scratch/exercises/$name\") == 0 || true;
}" 'plant()'
  grade planter
  grade honest
  expect_full honest "graded after a submission that planted a link in the scratch folder"
  [[ $(sum) == "$before" ]] || problem "planter: the grader wrote through the planted link"

  # A scratch CMakeCache.txt spoilt for the next submission.
  patched saboteur "#include <fstream>
static bool spoil() {
  std::ofstream(\"$scratch/build/CMakeCache.txt\") << \"spoilt\";
  return true;
}" 'spoil()'
  grade saboteur
  grade honest
  expect_full honest "graded after a submission that spoilt the scratch folder's CMakeCache.txt"

  # The hidden tests' binary and objects are root's alone.
  nobody test -r "$copy/grade-cases" && problem "nobody can read the grading binary"
  readable=$(nobody find "$copy/tests/grade/CMakeFiles/clothlab_grade_tests.dir" -name '*.o' \
    -readable 2>/dev/null | head -n 1 || true)
  [[ -z $readable ]] || problem "nobody can read the grading tests' objects: $readable"

  # --sandbox off runs the code as root: refused, unless said twice.
  grade honest --sandbox off
  [[ $code == 2 ]] || problem "--sandbox off as root: exit $code, expected a refusal (2)"
  grep -q -- '--kernels-as-root' "$work/honest.out" || problem "--sandbox off: the refusal does not say how"
  grade honest --sandbox off --kernels-as-root
  expect_full honest "--sandbox off --kernels-as-root"
  grep -q 'WARNING: no sandbox (--sandbox off)' "$work/honest.out" ||
    problem "--sandbox off --kernels-as-root: no warning"
  # Even as root, the kernels write no file: not the grading binary.
  patched replacer "#include <fstream>
static bool replace() {
  std::ofstream(\"$copy/grade-cases\") << \"replaced\";
  return true;
}" 'replace()'
  grade replacer --sandbox off --kernels-as-root
  [[ $(sum) == "$before" ]] || problem "the grading binary changed"
fi

if ((${#problems[@]} > 0)); then
  printf 'check_confinement: %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "every submission was bounded as a whole, and kept from the grader's files"
