# submission_checks.sh: what the grader's submission checks share (check_hostile.sh,
# check_confinement.sh, check_wire.sh, check_planted.sh), sourced after their `set -euo pipefail`. Takes the
# scripts' arguments CLOTHLAB SOURCE WORK_DIR into $clothlab, $source_dir and $work (a work folder
# made anew), and gives them problem MESSAGE, which collects a failure to report at the end, and
# score_of RESULTS_JSON, the score in a results.json, read by CMake's JSON parser (which also
# proves the file valid).
clothlab=$1
source_dir=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
problems=()
problem() { problems+=("$*"); }

cat >"$work/score.cmake" <<'CMAKE'
file(READ ${FILE} json)
string(JSON score ERROR_VARIABLE bad GET "${json}" score)
if(bad)
  message(FATAL_ERROR "not valid JSON: ${bad}")
endif()
message("${score}")
CMAKE
score_of() { cmake -DFILE="$1" -P "$work/score.cmake" 2>&1; }
