#!/usr/bin/env bash
# Re-runs a recorded session offline: lcm-logplayer replays the log's source channels on a bus of
# its own, and the downstream processes run on that bus, so a session can be studied again with
# other parameters; lcm-logger records the re-run, and sg-report reports on it.
#
#   scripts/replay.sh LOG [--from vision|predictor|grasp] [--port N] [--speed X] [--out LOG2]
#                         [-- ARGS for the first downstream process]
#
# By default the replay starts after the stage whose messages the log holds: with camera images
# (CAMERA_LEFT/RIGHT, recorded by `scripts/demo.sh --with-images`), from sg-vision on, with the
# calibration found beside the log (SESSION.calibration.yaml, or --calibration FILE); with
# positions only (OBJECT_POSITION), from sg-predictor on. Only the channels upstream of that stage
# are replayed (GROUND_TRUTH too, for the report), so nothing is published twice. --from grasp
# replays OBJECT_TRAJECTORY, OBJECT_POSITION and ARM_STATUS into sg-grasp (its commands are
# recorded, not executed: no arm is on the replay's bus).
#
# The replay needs no lab key: it runs in a private network namespace (scripts/multicast.sh run),
# whose bus nothing outside it can hear or reach, and its processes believe the log as it was
# recorded (--insecure-no-key; its messages' counters are old, so a guarded process would refuse
# them as stale: docs/security.md, "Replays").
#
# Examples:
#   scripts/replay.sh logs/20261126-015724-demo.lcmlog
#   scripts/replay.sh logs/…-demo.lcmlog --from predictor -- --model kalman   # a baseline
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
[ $# -ge 1 ] || { usage >&2; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
log="$1"
shift
from=""
port=7690
speed=1
out=""
calibration=""
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --from) from="$2"; shift ;;
    --port) port="$2"; shift ;;
    --speed) speed="$2"; shift ;;
    --out) out="$2"; shift ;;
    --calibration) calibration="$2"; shift ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) usage; exit 0 ;;
    *) echo "replay.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
[ -r "$log" ] || { echo "replay.sh: cannot read '$log'" >&2; exit 1; }

bin=build/bin
[ -x "$bin/sg-report" ] || scripts/bootstrap.sh
if [ -z "${SG_REPLAY_INSIDE:-}" ]; then  # a bus of its own: never the lab's
  SG_REPLAY_INSIDE=1 exec scripts/multicast.sh run "$0" "$log" --port "$port" --speed "$speed" \
    ${from:+--from "$from"} ${out:+--out "$out"} ${calibration:+--calibration "$calibration"} \
    -- "${extra[@]}"
fi

channels=$("$bin/sg-report" channels "$log")
has() { grep -q "^$1 " <<< "$channels"; }
if [ -z "$from" ]; then
  if has CAMERA_LEFT && has CAMERA_RIGHT; then from=vision
  elif has OBJECT_POSITION; then from=predictor
  else
    echo "replay.sh: $log holds neither camera images nor OBJECT_POSITION; nothing to replay" >&2
    exit 1
  fi
fi
session="${log%.lcmlog}"
case "$from" in
  vision)
    played='CAMERA_LEFT|CAMERA_RIGHT|GROUND_TRUTH|SIM_ARM_STATE'
    [ -n "$calibration" ] || calibration="$session.calibration.yaml"
    [ -r "$calibration" ] || { echo "replay.sh: no calibration '$calibration' (--calibration FILE)" >&2; exit 1; } ;;
  predictor) played='OBJECT_POSITION|GROUND_TRUTH|BLOB_LEFT|BLOB_RIGHT' ;;
  grasp) played='OBJECT_TRAJECTORY|OBJECT_POSITION|GROUND_TRUTH|ARM_STATUS' ;;
  *) echo "replay.sh: --from vision, predictor or grasp, not '$from'" >&2; exit 2 ;;
esac
[ -n "$out" ] || out="$session.replay-$from.lcmlog"

url="udpm://239.255.76.67:$port?ttl=0"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; }
trap cleanup EXIT

echo "replay: $log from $from on, on $url in a private network namespace; recording into $out"
echo "replay: its processes believe the log as recorded (--insecure-no-key): nothing here reaches a lab"
offline=(--insecure-no-key --log-level error)  # the INSECURE warning said once, above
lcm-logger --lcm-url="$url" --quiet -f "$out" > /dev/null &
logger_pid=$!
pids+=("$logger_pid")
first=("${extra[@]}")
if [ "$from" = vision ]; then
  "$bin/sg-vision" --lcm-url "$url" --calibration "$calibration" "${offline[@]}" "${first[@]}" &
  pids+=($!)
  first=()
fi
if [ "$from" = vision ] || [ "$from" = predictor ]; then
  coefficients=()  # the demo's offline-trained starting coefficients, when they are beside the log
  [ -r "$session.coefficients.yaml" ] && coefficients=(--coefficients "$session.coefficients.yaml")
  # --max-time-offset 0: the log's capture times are old, the plausibility gate must not refuse them
  "$bin/sg-predictor" --lcm-url "$url" "${offline[@]}" --max-time-offset 0 "${coefficients[@]}" \
    "${first[@]}" &
  pids+=($!)
  first=()
fi
"$bin/sg-grasp" --lcm-url "$url" "${offline[@]}" "${first[@]}" &
pids+=($!)
sleep 1
lcm-logplayer --lcm-url="$url" --speed="$speed" --regexp="^($played)\$" "$log"
sleep 1
for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
pids=()
echo "replay: done; the re-run is $out"
"$bin/sg-report" "$out"
