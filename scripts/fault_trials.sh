#!/usr/bin/env bash
# Issue 15's fault-injection table: the closed loop in simulation with real processes, one fault
# per run at a scripted moment of a grasp (kill -9 of each process and its restart, a serial
# disconnect, garbled serial bytes, dropped ACKs, 30% packet loss, a rogue publisher, two
# commanders, clock skew).
#
#   scripts/fault_trials.sh [--build-dir DIR] [--no-build] [--filter GTEST_FILTER]
#
# Each run checks sg-c550-sim's command log (no motion sent twice, none outside the limits), that
# no sequence was executed by two driver instances, and where the commander falls silent, that
# the arm is at rest within the watchdog's silence plus one controller interaction. It prints the
# markdown table of docs/reliability.md (one row a run); the full output is kept in logs/.
# The runs are tests/integration/fault_injection_test.cpp (also part of scripts/test.sh); they
# need root inside a private network namespace for iptables (scripts/multicast.sh run), and
# iptables and faketime (scripts/bootstrap.sh installs both).
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
build=1
filter='*'
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift ;;
    --no-build) build=0 ;;
    --filter) filter="$2"; shift ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "fault_trials.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

if [ -z "${SG_FAULT_TRIALS_INSIDE:-}" ]; then
  if [ "$build" -eq 1 ]; then
    scripts/bootstrap.sh --no-build
    cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release > /dev/null
    cmake --build "$build_dir" -j "$(nproc)" --target integration_fault_injection_test sg-keygen
  fi
  SG_FAULT_TRIALS_INSIDE=1 exec scripts/multicast.sh run "$0" --build-dir "$build_dir" \
    --no-build --filter "$filter"
fi

bin="$build_dir/bin"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ -z "${SG_LAB_KEY:-}" ]; then
  export SG_LAB_KEY="$work/lab.key"
  "$bin/sg-keygen" "$SG_LAB_KEY" > /dev/null
fi
mkdir -p logs
out="logs/$(date +%Y%m%d-%H%M%S)-fault-trials.txt"
echo "fault_trials: full output in $out"
export SG_FAULT_TABLE="$work/table.md"
status=0
gtest_filter=$(echo "$filter" | sed 's/\([^:]*\)/FaultInjection.\1/g')
"$bin/integration_fault_injection_test" --gtest_filter="$gtest_filter" > "$out" 2>&1 ||
  status=$?
echo "| fault | moment | what the arm did | sg-c550-sim's command log | reported |"
echo "|---|---|---|---|---|"
cat "$SG_FAULT_TABLE" 2>/dev/null || true
grep -E '^\[  (PASSED|FAILED)  \]' "$out" || true
if [ "$status" -ne 0 ]; then
  echo "fault_trials: FAILED (see $out)" >&2
  grep -B2 -A6 'Failure$' "$out" | head -80 >&2 || true
fi
exit "$status"
