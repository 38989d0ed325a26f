#!/usr/bin/env bash
# Builds the scene fuzzer (preset "fuzz": clang, libFuzzer, address + undefined sanitizers) and
# runs it for SECONDS seconds, starting from every lesson scene and every bad scene.
#
#   tests/fuzz/run-fuzz.sh SECONDS [extra libFuzzer flags...]
#
# Inputs that crash, hang or run out of memory are written to build-fuzz/fuzz/crashes/; the
# script then exits non-zero. Re-run one with: ./build-fuzz/fuzz-scene FILE
# The corpus the fuzzer grows is kept in build-fuzz/fuzz/corpus/, so a later run goes on from it.
set -euo pipefail
cd "$(dirname "$0")/../.."

if [[ $# -lt 1 || ! $1 =~ ^[0-9]+$ ]]; then
  echo "usage: $0 SECONDS [libFuzzer flags...]" >&2
  exit 2
fi
seconds=$1
shift

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz

work=build-fuzz/fuzz
mkdir -p "$work/corpus" "$work/crashes"
# The seeds are copied afresh each run, so they follow the scenes in the repository.
rm -rf "$work/seeds"
mkdir -p "$work/seeds"
for scene in lessons/*/*.toml tests/scenes/*.toml tests/scenes/bad/*.toml; do
  [[ -f $scene ]] || continue
  cp "$scene" "$work/seeds/$(echo "${scene%.toml}" | tr / _).toml"
done

# -timeout: one input stepping for longer than 20 s is reported as a hang.
# -rss_limit_mb: a scene that needs more memory than this is reported (the default is 2048).
status=0
./build-fuzz/fuzz-scene -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 \
  -dict=tests/fuzz/scene.dict -artifact_prefix="$work/crashes/" -print_final_stats=1 \
  "$@" "$work/corpus" "$work/seeds" || status=$?

if [[ $status -ne 0 ]]; then
  echo "fuzz-scene found a failing input (exit $status); see $work/crashes/:" >&2
  ls -l "$work/crashes/" >&2
fi
exit $status
