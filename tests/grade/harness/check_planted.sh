#!/usr/bin/env bash
# check_planted.sh CLOTHLAB SOURCE WORK_DIR PLANTS [--parse-only]: grades submissions made from
# copies of solutions/ with planted mistakes, and checks that each scores what PLANTS says it must.
# PLANTS (tests/grade/harness/planted/*.txt) holds blocks of two kinds:
#
#   mutant exNN.k FILE: what the mistake is
#   - one line of solutions/FILE, as it is (leading spaces aside; it must occur exactly once)
#   + the line that replaces it
#   ? an extended regular expression that a line of the grader's output must match (any number:
#     the hint that names this mistake, say)
#   ! no hint check: why this mistake has no "?" line
#
# a copy of solutions/FILE with that one line changed, graded on exercise exNN.k alone: it must
# compile and lose points there (a grading case that still gives full marks cannot tell the
# mistake from the right answer), and its report must match each "?" line. A mutant needs at least
# one "?" line, or a "!" line that says why it has none: a planted mistake whose report is never
# read could lose its hint unnoticed. Such a PLANTS file is refused before anything is graded.
#
#   submission NAME: what its kernels do
#   region FILE exNN.k
#     the body that replaces the region between "BEGIN exNN.k" and "END exNN.k"
#   region ...
#
# every file of solutions/ with each listed region replaced (a file with two regions of one ID
# lists two bodies, in order) and kNaN defined as a quiet NaN, graded on every exercise, hidden
# cases included: it must compile and score 0 overall (a kernel that computes nothing earns
# nothing).
#
# --parse-only reads PLANTS and checks what it says (each planted line found, each mutant's hint
# check) without grading anything: CLOTHLAB is not run.
set -euo pipefail
source "$(dirname "$0")/submission_checks.sh"
source "$(dirname "$0")/plant.sh"
plants=$4
parse_only=false
case ${5:-} in
  "") ;;
  --parse-only) parse_only=true ;;
  *) echo "check_planted: unknown option \"$5\" (expected --parse-only)" >&2; exit 2 ;;
esac

# The results' total score, their maximum, and the cases that scored, from results.json (read
# with CMake's JSON parser, which the build has anyway).
cat >"$work/read_results.cmake" <<'CMAKE'
file(READ ${RESULTS} json)
string(JSON score GET "${json}" score)
string(JSON count LENGTH "${json}" tests)
set(max 0)
set(scored "")
if(count GREATER 0)
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    string(JSON points GET "${json}" tests ${i} max_score)
    math(EXPR max "${max} + ${points}")
    string(JSON got GET "${json}" tests ${i} score)
    if(NOT got EQUAL 0)
      string(JSON name GET "${json}" tests ${i} name)
      string(APPEND scored "\n    ${got} / ${points}  ${name}")
    endif()
  endforeach()
endif()
message("${score} ${max}${scored}")
CMAKE

# grade NAME ARGS...: grades the folder $work/NAME in one scratch folder (as an instructor grades
# a class in turn, so that an unchanged file is not compiled again); sets score, max and scored.
grade() {
  local name=$1
  shift
  if ! out=$(NO_COLOR=1 "$clothlab" grade --submission "$work/$name" --scratch "$work/scratch" \
    --results "$work/$name.json" --hidden "$@" 2>&1); then
    echo "$out"
    problem "$name: the grader failed"
    return 1
  fi
  if grep -q 'does not compile' <<<"$out"; then
    echo "$out"
    problem "$name: does not compile, so its score says nothing about the grading cases"
    return 1
  fi
  local summary
  summary=$(cmake -DRESULTS="$work/$name.json" -P "$work/read_results.cmake" 2>&1)
  read -r score max <<<"${summary%%$'\n'*}"
  [[ $summary == *$'\n'* ]] && scored=${summary#*$'\n'} || scored=""
}

# plant_regions FILE BODIES: replaces the regions of FILE in order with the bodies listed in the
# folder BODIES (files named ID.N, N counting from 1 for each ID).
plant_regions() {
  local file=$1 bodies=$2
  awk -v bodies="$bodies" '
    /\/\/ BEGIN ex[0-9][0-9]\.[0-9]+/ {
      print
      match($0, /ex[0-9][0-9]\.[0-9]+/)
      id = substr($0, RSTART, RLENGTH)
      body = bodies "/" id "." (++seen[id])
      while ((getline line < body) > 0) print line
      close(body)
      skipping = 1
      next
    }
    /\/\/ END ex[0-9][0-9]\.[0-9]+/ { skipping = 0 }
    !skipping { print }' "$file" >"$file.new"
  mv "$file.new" "$file"
}

# --- read PLANTS into folders to grade ---------------------------------------------------------
mutants=()     # name|exercise|what
declare -A expect_lines  # name -> the "?" patterns, one a line
declare -A no_hint       # name -> why it has no "?" line
declare -A mutant_at     # name -> the line of PLANTS that starts it
submissions=() # names
kind="" name="" file="" old=""
number=0
while IFS= read -r line || [[ -n $line ]]; do
  number=$((number + 1))
  if [[ $line =~ ^mutant\ (ex[0-9][0-9]\.[0-9]+)\ ([0-9][0-9]_[a-z_]+\.cpp):\ (.*)$ ]]; then
    kind=mutant
    name="mutant-$((${#mutants[@]} + 1))"
    mutant_at[$name]=$number
    file=${BASH_REMATCH[2]}
    mutants+=("$name|${BASH_REMATCH[1]}|${BASH_REMATCH[3]}")
    mkdir -p "$work/$name"
    cp "$source_dir/solutions/$file" "$work/$name/"
  elif [[ $kind == mutant && $line =~ ^-\ (.*)$ ]]; then
    old=${BASH_REMATCH[1]}
  elif [[ $kind == mutant && $line =~ ^\+\ (.*)$ ]]; then
    plant_line "$work/$name/$file" "$old" "${BASH_REMATCH[1]}" || true
  elif [[ $kind == mutant && $line =~ ^\?\ (.*)$ ]]; then
    expect_lines[$name]+="${BASH_REMATCH[1]}"$'\n'
  elif [[ $kind == mutant && $line =~ ^!\ no\ hint\ check:\ *(.*)$ ]]; then
    no_hint[$name]=${BASH_REMATCH[1]}
  elif [[ $line =~ ^submission\ ([a-z0-9-]+):\ (.*)$ ]]; then
    kind=submission
    name=${BASH_REMATCH[1]}
    submissions+=("$name|${BASH_REMATCH[2]}")
    mkdir -p "$work/$name/bodies"
    cp "$source_dir"/solutions/[0-9][0-9]_*.cpp "$work/$name/"
  elif [[ $kind == submission && $line =~ ^region\ ([0-9][0-9]_[a-z_]+\.cpp)\ (ex[0-9][0-9]\.[0-9]+)$ ]]; then
    file=${BASH_REMATCH[1]}
    id=${BASH_REMATCH[2]}
    n=1
    while [[ -e $work/$name/bodies/$file/$id.$n ]]; do n=$((n + 1)); done
    mkdir -p "$work/$name/bodies/$file"
    body=$work/$name/bodies/$file/$id.$n
    : >"$body"
  elif [[ $kind == submission && -n $file && $line =~ ^\ \ (.*)$ ]]; then
    printf '  %s\n' "${BASH_REMATCH[1]}" >>"$body"
  elif [[ -z $line || $line == \#* ]]; then
    continue
  else
    echo "check_planted: $plants:$number: cannot read the line \"$line\"" >&2
    exit 2
  fi
done <"$plants"

for entry in "${submissions[@]}"; do
  name=${entry%%|*}
  for f in "$work/$name"/[0-9][0-9]_*.cpp; do
    base=$(basename "$f")
    if [[ ! -d $work/$name/bodies/$base ]]; then
      problem "$name: $plants gives no bodies for $base"
      continue
    fi
    plant_regions "$f" "$work/$name/bodies/$base"
    { printf '#include <limits>\nnamespace {\n[[maybe_unused]] constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();\n}\n'; cat "$f"; } >"$f.new"
    mv "$f.new" "$f"
    # Every region of the file must have been replaced by a listed body.
    regions=$(grep -c '// BEGIN ex' "$f" || true)
    listed=$(ls "$work/$name/bodies/$base" | wc -l)
    [[ $regions -eq $listed ]] ||
      problem "$name: $base has $regions regions but $plants gives $listed bodies"
  done
  rm -rf "$work/$name/bodies"
done

# Every mutant reads its report: a "?" line, or a "!" line that says why not (and not both).
for entry in "${mutants[@]}"; do
  IFS='|' read -r name exercise what <<<"$entry"
  at="$(basename "$plants"):${mutant_at[$name]}: mutant $exercise ($what)"
  if [[ -v no_hint[$name] ]]; then
    if [[ -z ${no_hint[$name]// /} ]]; then
      problem "$at: its \"! no hint check:\" line gives no reason"
    elif [[ -n ${expect_lines[$name]:-} ]]; then
      problem "$at: has \"?\" lines and a \"! no hint check:\" line; keep one"
    fi
  elif [[ -z ${expect_lines[$name]:-} ]]; then
    problem "$at: no \"?\" line checks the grader's hint for this mistake; add one (what" \
      "the report must say of it), or a line \"! no hint check: WHY\""
  fi
done
if [[ ${#problems[@]} -gt 0 ]]; then
  echo "check_planted: $plants, nothing graded:" >&2
  printf '  %s\n' "${problems[@]}" >&2
  exit 1
fi
if $parse_only; then
  echo "check_planted: $(basename "$plants") reads well: ${#mutants[@]} mutants, each with its" \
    "hint check or the reason it has none, and ${#submissions[@]} submissions"
  exit 0
fi

# --- grade them --------------------------------------------------------------------------------
for entry in "${mutants[@]}"; do
  IFS='|' read -r name exercise what <<<"$entry"
  echo "== $name, $exercise: $what"
  grade "$name" --exercise "$exercise" || continue
  echo "   $score / $max points$([[ -n $scored ]] && printf '%s' ", scored by:"$'\n'"$scored")"
  if [[ $max -eq 0 ]]; then
    problem "$name ($exercise): no cases were graded"
  elif [[ $score -ge $max ]]; then
    problem "$name ($exercise: $what) keeps full marks, $score / $max"
  fi
  while IFS= read -r pattern; do
    [[ -z $pattern ]] && continue
    grep -Eq -- "$pattern" <<<"$out" ||
      problem "$name ($exercise: $what): no line of the grader's output matches \"$pattern\""
  done <<<"${expect_lines[$name]:-}"
done
for entry in "${submissions[@]}"; do
  IFS='|' read -r name what <<<"$entry"
  echo "== $name: $what"
  grade "$name" || continue
  echo "   $score / $max points$([[ -n $scored ]] && printf '%s' ", scored by:"$'\n'"$scored")"
  [[ $score -eq 0 ]] || problem "$name ($what) scores $score / $max, expected 0, by:"$'\n'"$scored"
done

if [[ ${#problems[@]} -gt 0 ]]; then
  echo "check_planted: $(basename "$plants"):" >&2
  printf '  %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "check_planted: every planted submission of $(basename "$plants") scored as it must"
