#!/usr/bin/env bash
# try-gradescope-root.sh: the Gradescope autograder, tried as Gradescope runs it, in a fresh
# Debian 12 root. Run by hand (it needs root, the network and up to half an hour, most of it
# setup.sh compiling the engine); no test runs it.
#
#   sudo tests/tools/try-gradescope-root.sh [--cache DIR] [--mirror URL] [--fresh] BUILD_DIR
#
# BUILD_DIR is a configured build of this project: the script builds its gradescope-autograder
# target. Then:
#   1. a Debian 12 root (debootstrap --variant=minbase bookworm), made once and kept in
#      DIR/bookworm (DIR: --cache, default /var/tmp/clothlab-gradescope); the mirror is the first
#      Debian one in this machine's apt sources, or --mirror. Each run works on an overlay of it
#      (DIR/run/), so the kept root stays fresh; downloaded packages are kept in DIR/apt-archives;
#   2. the bundle unzipped in /autograder/source, run_autograder copied to /autograder, and
#      setup.sh run as root, as Gradescope builds its image (skipped when DIR/run holds a root set
#      up from the same bundle, unless --fresh);
#   3. a submission in /autograder/submission, lesson 01 solved and lesson 02's file broken (it
#      does not compile), graded by /autograder/run_autograder in three containers:
#        namespaces     a mount and PID namespace whose root is the Debian root (pivot_root):
#                       the grader's sandbox can work;
#        no-namespaces  the same, under forbid_namespaces (tests/tools/forbid_namespaces.cpp):
#                       what Docker's default seccomp profile refuses a container without
#                       CAP_SYS_ADMIN, the calls that make a namespace among them;
#        chroot         chroot(8): Linux makes no user namespace for a chrooted process;
#   4. the same files graded as the student grades them (`clothlab grade` with them in
#      exercises/), and each container's results.json compared with it, exercise by exercise and
#      case by case (its visible cases; the hidden ones the student's grading does not run).
# It prints the time of each step, each container's score and the sandbox's warnings, and exits 1
# if a container's results differ from the student's grade.
set -euo pipefail
cache=/var/tmp/clothlab-gradescope
mirror=
fresh=0
while [[ $# -gt 1 ]]; do
  case $1 in
  --cache) cache=$2; shift 2 ;;
  --mirror) mirror=$2; shift 2 ;;
  --fresh) fresh=1; shift ;;
  *) break ;;
  esac
done
if [[ $# -ne 1 ]]; then
  echo "usage: $0 [--cache DIR] [--mirror URL] [--fresh] BUILD_DIR" >&2
  exit 2
fi
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
say() { printf '\n== %s\n' "$*"; }
die() {
  echo "try-gradescope-root: $*" >&2
  exit 1
}
[[ $(id -u) -eq 0 ]] || die "run it as root: it makes a root, mounts and chroots"
for tool in debootstrap unshare pivot_root mount g++ /usr/bin/python3; do
  command -v "$tool" >/dev/null || die "it needs $tool"
done
case $cache in
"$source_dir" | "$source_dir"/*) die "keep the cache outside the repository ($cache)" ;;
esac
mkdir -p "$cache"
cache=$(cd "$cache" && pwd)
seconds() { date +%s.%N; }
elapsed() { /usr/bin/python3 -c 'import sys; print(f"{float(sys.argv[2]) - float(sys.argv[1]):.0f} s")' "$@"; }
declare -A took

# --- 1. the Debian 12 root -----------------------------------------------------------------------
base=$cache/bookworm
if [[ -z $mirror ]]; then
  # The first Debian mirror of this machine's apt sources (one-line or deb822 files).
  mirror=$({ cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list \
    /etc/apt/sources.list.d/*.sources 2>/dev/null || true; } |
    sed -nE 's/^(deb +(\[[^]]*\] +)?|URIs: *)([^ ]+\/debian)\/?( .*)?$/\3/p' | head -1)
  [[ -n $mirror ]] || die "no Debian mirror in /etc/apt/sources*: give one with --mirror URL"
fi
if [[ ! -f $base/.bootstrapped ]]; then
  say "bootstrapping Debian 12 into $base (debootstrap --variant=minbase bookworm, from $mirror)"
  rm -rf "$base.partial"
  start=$(seconds)
  debootstrap --variant=minbase bookworm "$base.partial" "$mirror" >"$cache/debootstrap.log" 2>&1 || {
    tail -20 "$cache/debootstrap.log"
    die "debootstrap failed (its log: $cache/debootstrap.log)"
  }
  took[bootstrap]=$(elapsed "$start" "$(seconds)")
  date -u >"$base.partial/.bootstrapped"
  rm -rf "$base"
  mv "$base.partial" "$base"
else
  took[bootstrap]="kept from $(cat "$base/.bootstrapped")"
fi
# The updates and security suites, as a Debian image has them.
security=${mirror%/debian}/debian-security
printf 'deb %s bookworm bookworm-updates main\ndeb %s bookworm-security main\n' "$mirror" \
  "$security" >"$base/etc/apt/sources.list"

# --- 2. the bundle, set up ----------------------------------------------------------------------
say "building the bundle (cmake --build $build --target gradescope-autograder)"
cmake --build "$build" --parallel "$(nproc)" --target gradescope-autograder >/dev/null
bundle=$build/gradescope-autograder.zip
# What the bundle holds, not the zip's bytes (which carry the time of each export).
bundle_sum=$(cd "$build/gradescope-autograder" && find . -type f -print0 | sort -z |
  xargs -0 sha256sum | sha256sum | cut -d' ' -f1)
g++ -std=c++20 -O2 -Wall -Wextra -Werror -static -o "$cache/forbid_namespaces" \
  "$source_dir/tests/tools/forbid_namespaces.cpp"

run=$cache/run
root=$run/root
mkdir -p "$cache/apt-archives/partial"
cleanup() {
  mountpoint -q "$root" && umount "$root"
  return 0
}
trap cleanup EXIT
cleanup
if [[ $fresh -eq 1 || ! -f $run/upper/.set-up || $(cat "$run/upper/.set-up") != "$bundle_sum" ]]; then
  rm -rf "$run"
fi
mkdir -p "$run/upper" "$run/work" "$root"
mount -t overlay overlay -o "lowerdir=$base,upperdir=$run/upper,workdir=$run/work" "$root"
cp -L /etc/resolv.conf "$root/etc/resolv.conf"
mkdir -p "$root/usr/local/sbin"
cp "$cache/forbid_namespaces" "$root/usr/local/sbin/"

# in_root MODE COMMAND: runs the bash command line COMMAND in the root, as root, in a container of
# kind MODE (namespaces, no-namespaces or chroot; see the top of this file), with a fresh /proc, the
# machine's /dev and network, and the package cache. Every mount is gone when it ends.
in_root() {
  local mode=$1 command=$2 wrap=
  [[ $mode == no-namespaces ]] && wrap=/usr/local/sbin/forbid_namespaces
  # shellcheck disable=SC2016 # expanded by the inner shell
  unshare --mount --pid --fork --kill-child /bin/sh -c '
    set -e
    root=$1 mode=$2 archives=$3 wrap=$4 command=$5
    mount --make-rprivate /
    [ "$mode" = chroot ] || mount --bind "$root" "$root"  # a mount point to pivot_root into
    mount --rbind /dev "$root/dev"
    mount -t proc proc "$root/proc"
    mount --bind "$archives" "$root/var/cache/apt/archives"
    env="/usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8"
    if [ "$mode" = chroot ]; then
      exec chroot "$root" $env /bin/bash -c "$command"
    fi
    cd "$root"
    mkdir -p .old-root
    pivot_root . .old-root
    cd /
    umount -l /.old-root
    rmdir /.old-root
    exec $wrap $env /bin/bash -c "$command"
  ' in_root "$root" "$mode" "$cache/apt-archives" "$wrap" "$command"
}

if [[ ! -f $run/upper/.set-up ]]; then
  say "unpacking the bundle in /autograder/source and running setup.sh (as Gradescope builds its image)"
  mkdir -p "$root/autograder/source"
  (cd "$root/autograder/source" && cmake -E tar xf "$bundle")
  cp "$root/autograder/source/run_autograder" "$root/autograder/run_autograder"
  start=$(seconds)
  in_root namespaces 'cd /autograder/source && bash ./setup.sh' >"$run/setup.log" 2>&1 || {
    tail -30 "$run/setup.log"
    die "setup.sh failed (its log: $run/setup.log)"
  }
  took[setup.sh]=$(elapsed "$start" "$(seconds)")
  echo "$bundle_sum" >"$run/upper/.set-up"
else
  took[setup.sh]="kept from an earlier run on the same bundle"
fi

# --- 3. the submission, graded in each container ------------------------------------------------
submission=$root/autograder/submission
rm -rf "$submission" "$root/autograder/student.json"
mkdir -p "$submission"
cp "$source_dir"/solutions/01_*.cpp "$submission/"
cp "$source_dir"/solutions/02_*.cpp "$submission/"
broken=$(basename "$submission"/02_*.cpp)
echo 'double typo = 1.0 +;  // a line that does not compile' >>"$submission/$broken"
results=$run/results
rm -rf "$results"
mkdir -p "$results"
for mode in namespaces no-namespaces chroot; do
  say "run_autograder, in a container with $mode"
  rm -rf "$root/autograder/results"
  start=$(seconds)
  in_root "$mode" 'cd /autograder && ./run_autograder' >"$results/$mode.log" 2>&1 ||
    echo "(run_autograder exited with $?)"
  took["grading, $mode"]=$(elapsed "$start" "$(seconds)")
  [[ -f $root/autograder/results/results.json ]] ||
    die "run_autograder wrote no results.json with $mode: $(tail -20 "$results/$mode.log")"
  cp "$root/autograder/results/results.json" "$results/$mode.json"
  grep -i -E 'warning|sandbox' "$results/$mode.log" | head -5 || echo "(no warning about the sandbox)"
done

say "without namespaces: what --sandbox on does, and what the user nobody may read"
# shellcheck disable=SC2016 # expanded in the root
in_root no-namespaces '
  cd /autograder/source/clothlab
  NO_COLOR=1 ./build/clothlab grade --submission /autograder/submission --scratch /tmp/probe \
    --exercise ex01 --sandbox on 2>&1 | tail -3
  echo "(exit status ${PIPESTATUS[0]})"
  for path in tests/grade-hidden build/grade-cases tests/grade exercises; do
    if setpriv --reuid=65534 --regid=65534 --clear-groups test -r "$path"; then
      echo "nobody may read $path"
    else
      echo "nobody may not read $path"
    fi
  done' 2>&1 | tee "$results/no-namespaces-probe.log"

say "the same files graded as the student grades them (clothlab grade, the files in exercises/)"
# exercises/ as the student has it: the shipped stubs, with the submission's files over them.
start=$(seconds)
in_root namespaces '
  set -e
  rm -rf /autograder/student-exercises
  cp -r /autograder/source/clothlab/exercises /autograder/student-exercises
  cp /autograder/submission/*.cpp /autograder/student-exercises/
  cd /autograder/source/clothlab
  NO_COLOR=1 ./build/clothlab grade --exercises /autograder/student-exercises \
    --results /autograder/student.json' >"$results/student.log" 2>&1 || true
took["grading, the student's"]=$(elapsed "$start" "$(seconds)")
[[ -f $root/autograder/student.json ]] || die "the student's grading wrote nothing: $(tail -20 "$results/student.log")"
cp "$root/autograder/student.json" "$results/student.json"

say "times"
for step in bootstrap setup.sh "grading, namespaces" "grading, no-namespaces" "grading, chroot" \
  "grading, the student's"; do
  printf '  %-24s %s\n' "$step" "${took[$step]}"
done

say "results.json against the student's grade"
/usr/bin/python3 - "$results" <<'EOF'
import json, re, sys
from collections import defaultdict

folder = sys.argv[1]
def load(name):
    with open(f"{folder}/{name}.json") as f:
        return json.load(f)

def per_case(report, visible_only):
    cases = {}
    for t in report["tests"]:
        if visible_only and t.get("visibility", "visible") != "visible":
            continue
        cases[t["name"]] = (t["score"], t["max_score"])
    return cases

def per_exercise(cases):
    points = defaultdict(lambda: [0, 0])
    for name, (score, most) in cases.items():
        lesson = re.match(r"(ex\d\d)", name).group(1)
        points[lesson][0] += score
        points[lesson][1] += most
    return points

student = per_case(load("student"), visible_only=False)
want = per_exercise(student)
print("  student's grade: " + ", ".join(f"{k} {v[0]:g}/{v[1]:g}" for k, v in sorted(want.items())
                                         if v[0] or k in ("ex01", "ex02")) +
      f"; total {sum(v[0] for v in want.values()):g} / {sum(v[1] for v in want.values()):g}")
differ = False
for mode in ("namespaces", "no-namespaces", "chroot"):
    report = load(mode)
    visible = per_case(report, visible_only=True)
    got = per_exercise(visible)
    hidden = sum(1 for t in report["tests"] if t.get("visibility", "visible") != "visible")
    cases_differ = sorted(n for n in set(student) | set(visible) if student.get(n) != visible.get(n))
    same = not cases_differ
    differ |= not same
    print(f"  {mode:14} score {report['score']:g} (visible: "
          + ", ".join(f"{k} {v[0]:g}/{v[1]:g}" for k, v in sorted(got.items()) if v[0] or k in ("ex01", "ex02"))
          + f"; {hidden} hidden cases): "
          + ("the same, case by case" if same else "DIFFERS: " + "; ".join(cases_differ[:5])))
    ex02 = [t for t in report["tests"] if t["name"].startswith("ex02")]
    if ex02 and not all(t["score"] == 0 for t in ex02):
        print(f"  {mode}: ex02 (the broken file) has points")
        differ = True
    if not any("not compiled" in t.get("output", "") or "not compiled" in t.get("status", "")
               for t in ex02):
        print(f"  {mode}: ex02's tests do not say it did not compile")
        differ = True
sys.exit(1 if differ else 0)
EOF
echo "(the logs and reports: $results)"
