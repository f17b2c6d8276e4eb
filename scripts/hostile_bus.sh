#!/usr/bin/env bash
# Issue 15's first figure, full size: a hostile bus against the system at rest in simulation.
#
#   scripts/hostile_bus.sh [--random-bodies K] [--build-dir DIR] [--no-build] [--insecure]
#
# sg-c550-sim (a pseudo-terminal), sg-arm-driver, sg-grasp (idle), sg-predictor, sg-vision and
# sg-camera-sim run on a private multicast bus; `sg-bus-check hostile` then sends, on each of the
# twelve channels they read, every 4-byte window of a typical message of the channel's type set to
# 0, -1, 2^31-1 and 10^9, K random bodies (default 1000) behind the type's fingerprint, every
# truncation and the other types' messages (19,085 packets at K = 1000, 2000 a second). It prints
# a table: each process, alive or not, its RSS at rest and at its peak during the attack (sampled
# every 50 ms), the decode and handler errors its PROCESS_STATUS reports ("-": the process does
# not report one), and the arm's joints before and after. Exit 0 when every process is alive,
# none grew by 100 MB, the arm did not move and each reporting process counted decode errors.
#
# The run is tests/integration/hostile_bus_test.cpp with K raised ($HOSTILE_BUS_RANDOM_BODIES);
# its full output is kept in logs/. Commands are signed with $SG_LAB_KEY or
# ~/.config/stereograsp/lab.key, else a key made for the run. --insecure runs the driver and
# sg-grasp with --insecure-no-key (unsigned commands obeyed): what the attack does without
# signing. docs/reliability.md holds the measured table.
set -euo pipefail
cd "$(dirname "$0")/.."

random_bodies=1000
build_dir=build
build=1
insecure=0
while [ $# -gt 0 ]; do
  case "$1" in
    --random-bodies) random_bodies="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --no-build) build=0 ;;
    --insecure) insecure=1 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "hostile_bus.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

# The attack never leaves a private network namespace: it must not meet a running system's bus.
if [ -z "${SG_HOSTILE_BUS_INSIDE:-}" ]; then
  if [ "$build" -eq 1 ]; then
    scripts/bootstrap.sh --no-build
    cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release > /dev/null
    cmake --build "$build_dir" -j "$(nproc)" --target integration_hostile_bus_test sg-keygen \
      sg-bus-check sg-c550-sim sg-arm-driver sg-grasp sg-predictor sg-vision sg-camera-sim
  fi
  args=(--random-bodies "$random_bodies" --build-dir "$build_dir" --no-build)
  [ "$insecure" -eq 1 ] && args+=(--insecure)
  SG_HOSTILE_BUS_INSIDE=1 exec scripts/multicast.sh run "$0" "${args[@]}"
fi

bin="$build_dir/bin"
key_dir=""
trap '[ -z "$key_dir" ] || rm -rf "$key_dir"' EXIT
default_key=${SG_LAB_KEY:-${HOME:-/nonexistent}/.config/stereograsp/lab.key}
if [ -e "$default_key" ]; then
  export SG_LAB_KEY="$default_key"
else
  key_dir=$(mktemp -d)
  export SG_LAB_KEY="$key_dir/lab.key"
  "$bin/sg-keygen" "$SG_LAB_KEY" > /dev/null
fi

mkdir -p logs
out="logs/$(date +%Y%m%d-%H%M%S)-hostile-bus.txt"
echo "hostile_bus: K = $random_bodies random bodies per type$([ "$insecure" -eq 1 ] && echo ', --insecure: unsigned commands obeyed'); full output in $out"
status=0
HOSTILE_BUS_RANDOM_BODIES="$random_bodies" HOSTILE_BUS_INSECURE="$insecure" \
  "$bin/integration_hostile_bus_test" > "$out" 2>&1 || status=$?
# The test prints the attacker's summary, the table and the joints (between "hostile: sent" and
# the command count), then gtest's verdict.
sed -n '/^hostile: sent/,/^RAPL-II commands/p' "$out"
grep -E '^\[  (PASSED|FAILED)  \]|Failure$' "$out" | sort | uniq -c | sed 's/^ *//' || true
if [ "$status" -ne 0 ]; then
  echo "hostile_bus: FAILED (see $out)" >&2
  grep -A4 'Failure$' "$out" | head -60 >&2 || true
fi
exit "$status"
