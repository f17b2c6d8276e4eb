#!/usr/bin/env bash
# scripts/replay.sh on a session recorded from vouched processes, with no lab key anywhere in the
# replay's environment: sg-camera-sim and sg-vision (with a key) are recorded by lcm-logger for
# 6 s, then the log is replayed from sg-predictor on, in its private namespace. The re-run must
# hold OBJECT_TRAJECTORY (sg-predictor believed the recorded positions) and GRASP_STATUS (sg-grasp
# ran: it used to stop at "lab key ...: no such file"), and say nothing of a missing key.
#
#   tests/integration/replay_test.sh BUILD_DIR     (inside scripts/multicast.sh run; SG_LAB_KEY)
set -euo pipefail

[ $# -eq 1 ] || { echo "usage: replay_test.sh BUILD_DIR" >&2; exit 2; }
build_dir=$(realpath "$1")
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
bin=$build_dir/bin
work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; rm -rf "$work"' EXIT
fail() { echo "replay_test: FAILED: $*" >&2; [ -e "$work/replay.txt" ] && tail -30 "$work/replay.txt" >&2; exit 1; }

url="udpm://239.255.76.67:7941?ttl=0"
"$bin/sg-camera-sim" --calibration-out "$work/cams.yaml" --snapshot "$work/pair.png" \
  --log-level warn > /dev/null
lcm-logger --lcm-url="$url" --quiet -f "$work/session.lcmlog" > /dev/null & pids+=($!)
"$bin/sg-vision" --lcm-url "$url" --calibration "$work/cams.yaml" --log-level warn & pids+=($!)
"$bin/sg-camera-sim" --lcm-url "$url" --rate 10 --frames 60 --log-level warn > /dev/null
for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
pids=()
"$bin/sg-report" channels "$work/session.lcmlog" > "$work/recorded.txt"
grep -q '^OBJECT_POSITION ' "$work/recorded.txt" || fail "no OBJECT_POSITION recorded"

# The replay: no lab key in its environment, none in HOME.
status=0
env -u SG_LAB_KEY HOME="$work/home" "$source_dir/scripts/replay.sh" "$work/session.lcmlog" \
  --from predictor --port 7942 --speed 2 --out "$work/replay.lcmlog" > "$work/replay.txt" 2>&1 ||
  status=$?
[ "$status" -eq 0 ] || fail "replay.sh exited $status"
! grep -q 'no such file' "$work/replay.txt" || fail "a program asked for a lab key"
"$bin/sg-report" channels "$work/replay.lcmlog" > "$work/replayed.txt"
grep -q '^OBJECT_TRAJECTORY ' "$work/replayed.txt" || fail "no OBJECT_TRAJECTORY in the re-run"
grep -q '^GRASP_STATUS ' "$work/replayed.txt" || fail "no GRASP_STATUS: sg-grasp did not run"
echo "replay_test: passed: $(grep -c . "$work/replayed.txt") channels in the re-run"
