# plant.sh: plant_line, sourced by check_planted.sh and tests/tools/make_class.sh; the caller
# defines problem MESSAGE.
# plant_line FILE OLD NEW: replaces the one line of FILE that reads OLD (leading spaces aside)
# with NEW, indented as it was.
plant_line() {
  local file=$1 old=$2 new=$3 count
  count=$(awk -v old="$old" '{ s = $0; sub(/^[ \t]+/, "", s); if (s == old) n++ } END { print n + 0 }' "$file")
  if [[ $count -ne 1 ]]; then
    problem "$(basename "$file"): the line \"$old\" occurs $count times (expected once)"
    return 1
  fi
  awk -v old="$old" -v new="$new" '{
    s = $0; sub(/^[ \t]+/, "", s)
    if (s == old) { match($0, /^[ \t]*/); print substr($0, 1, RLENGTH) new } else print
  }' "$file" >"$file.new"
  mv "$file.new" "$file"
}

