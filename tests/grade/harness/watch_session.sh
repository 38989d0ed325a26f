# watch_session.sh: sourced by the checks that run `clothlab watch` in the background
# (check_student_loop.sh, check_watch_pages.sh); they define die MESSAGE.

# watch_waits LOG PID SECONDS: until the watch PID, writing to LOG, says it waits for a change;
# if it does not within SECONDS (or ends first), shows LOG and fails.
watch_waits() {
  local log=$1 pid=$2 tries=$(($3 * 5))
  for _ in $(seq "$tries"); do
    grep -q 'waiting for a change' "$log" && return 0
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.2
  done
  grep -q 'waiting for a change' "$log" && return 0
  cat "$log"
  kill "$pid" 2>/dev/null || true
  die "watch did not wait for a change"
}

# watch_ends LOG PID SECONDS WHAT: until the watch PID ends its last round; if it is still running
# after SECONDS, stops it, shows LOG and fails ("watch did not WHAT"); fails too if it exits with
# an error. Shows LOG.
watch_ends() {
  local log=$1 pid=$2 tries=$(($3 * 5)) what=$4
  for _ in $(seq "$tries"); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.2
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill "$pid"
    cat "$log"
    die "watch did not $what"
  fi
  wait "$pid" || die "watch exited with $?"
  cat "$log"
}
