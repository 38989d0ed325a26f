#!/usr/bin/env bash
# check_watch_pages.sh CLOTHLAB SOURCE BUILD EMCMAKE CMAKE WORK_DIR: `clothlab watch` rebuilds the
# student's live page when an exercise file is saved.
#
# On a folder of exercise files of its own (a scratch copy of the student's ex02, the other
# exercises the course's), with a web build of the student pages alone made for that folder
# (engine/web/CMakeLists.txt's ENGINE_FROM: it links the engine BUILD/web/ compiled, so only the
# exercise files are compiled here). Watch grades and builds the pages once, then the exercise file
# is saved solved: watch must say it rebuilt the pages, and lesson 02's student page must be
# newer than the save and hold another module than before. The course's exercises/ and the
# build's own pages are left as they were.
set -euo pipefail
clothlab=$1
source_dir=$2
build=$3
emcmake=$4
cmake=$5
work=$6
die() {
  echo "check_watch_pages: $*" >&2
  exit 1
}
source "$(dirname "$0")/watch_session.sh"
# What the scratch web build links: the engine BUILD/web/ compiled (and, where it is there, its
# lesson pages' module, for the student page's side-by-side mode).
[[ -f $build/web/libclothlab_web_engine_quick.a ]] ||
  die "no $build/web/libclothlab_web_engine_quick.a: build the live pages first (cmake --build $build --target web-student)"
rm -rf "$work"
mkdir -p "$work/exercises"
exercise=$work/exercises/02_spring_dampers.cpp
cp "$source_dir/exercises/02_spring_dampers.cpp" "$exercise"
page=$work/pages/02-spring-dampers-student.html
sums_before=$(sha256sum "$source_dir"/exercises/*)
own_pages_before=$(ls -l --time-style=full-iso "$build"/pages/*-student.html 2>/dev/null || true)
# Debian's emcc finds its JavaScript optimizer's parser among the system's node modules.
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}

echo "== a web build of the student pages alone, for $work/exercises/"
"$emcmake" "$cmake" -S "$source_dir/engine/web" -B "$work/web" -DEXERCISES_DIR="$work/exercises" \
  -DPAGES_DIR="$work/pages" -DENGINE_FROM="$build/web" >"$work/configure.log" 2>&1 || {
  cat "$work/configure.log"
  die "the web build of the student pages alone does not configure"
}

echo "== watch: graded and the pages built at the start, then again when the file is saved"
log=$work/watch.log
NO_COLOR=1 "$clothlab" watch ex02 --exercises "$work/exercises" --scratch "$work/scratch" \
  --web-build "$work/web" --rounds 2 >"$log" 2>&1 &
watcher=$!
watch_waits "$log" "$watcher" 600
[[ -f $page ]] || {
  cat "$log"
  kill "$watcher"
  die "watch's first round wrote no $page"
}
sum_before=$(sha256sum <"$page")
# The save comes a second after the page was written, so that "newer" cannot be a tie.
sleep 1.1
cp "$source_dir/solutions/02_spring_dampers.cpp" "$exercise"
saved=$(date +%s.%N)
watch_ends "$log" "$watcher" 600 "finish its second round after the file was saved"

grep -q '(02_spring_dampers.cpp changed)' "$log" || die "watch does not say which file changed"
grep -Eq '^ex02\.1 +6 / 6 +6 / 6 +done' "$log" || die "watch's second grading is not the solved file's"
# Both rounds rebuilt the pages and said where they are.
rebuilt=$(grep -c "^your live pages, rebuilt in [0-9.]* s: open .*pages/NN-name-student.html" "$log" || true)
[[ $rebuilt -eq 2 ]] || die "watch said it rebuilt the pages $rebuilt times in its two rounds, not 2"
grep -q 'could not be rebuilt' "$log" && die "a rebuild of the pages failed"
written=$(stat -c %.9Y "$page")
awk -v w="$written" -v s="$saved" 'BEGIN {exit !(w > s)}' ||
  die "$page was last written at $written, before the file was saved at $saved"
[[ $(sha256sum <"$page") != "$sum_before" ]] || die "$page is the same after the save as before"

[[ $sums_before == "$(sha256sum "$source_dir"/exercises/*)" ]] || die "the project's exercises/ changed"
[[ $own_pages_before == "$(ls -l --time-style=full-iso "$build"/pages/*-student.html 2>/dev/null || true)" ]] ||
  die "the build's own student pages were rewritten"
echo "watch rebuilds the student's page on save"
