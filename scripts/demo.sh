#!/usr/bin/env bash
# The most complete loop that runs on this machine without hardware, recorded by lcm-logger.
#
#   scripts/demo.sh [--seconds N] [--tag NAME] [--with-images]
#
# Today: a one-second check that every stereograsp message type crosses the LCM bus intact
# (sg-bus-check); then the simulated stereo cameras (sg-camera-sim) film the red ball on the
# paper's path -- a 0.15 m circle at 1 rpm plus a drift along Y, hidden by a passing panel for two
# seconds -- at 30 Hz; sg-vision finds the ball in both images and triangulates it with the
# cameras' calibration (BLOB_LEFT, BLOB_RIGHT, OBJECT_POSITION); sg-predictor forecasts its path
# 16 samples (4 s) ahead with Burg's linear predictors, carrying it through the occlusion
# (OBJECT_TRAJECTORY); sg-viewer records the paper's user interface, the prediction drawn in, to a
# video. The stock lcm-logger records the session into logs/ (camera images only with
# --with-images: they are large). The arm and grasping join as they land.
#
# The bus is LCM's default (or $LCM_DEFAULT_URL), so `scripts/spy.sh` in another terminal shows
# the channels while the demo runs.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${DEMO_SECONDS:-10}
tag=demo
with_images=0
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift ;;
    --tag) tag="$2"; shift ;;
    --with-images) with_images=1 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

scripts/bootstrap.sh
if ! scripts/multicast.sh setup; then
  echo "demo: no multicast here; running the demo in a private network namespace" >&2
  args=(--seconds "$seconds" --tag "$tag")
  [ "$with_images" -eq 1 ] && args+=(--with-images)
  exec scripts/multicast.sh run "$0" "${args[@]}"
fi

bin=build/bin
mkdir -p logs
session="logs/$(date +%Y%m%d-%H%M%S)-$tag"
log="$session.lcmlog"
url_args=()
[ -n "${LCM_DEFAULT_URL:-}" ] && url_args=(--lcm-url "$LCM_DEFAULT_URL")
logger_url=${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}

pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; }
trap cleanup EXIT

logger_args=(--lcm-url="$logger_url" --quiet)
[ "$with_images" -eq 1 ] || logger_args+=(-v -c 'CAMERA_.*')   # everything but the images
echo "demo: recording the bus ($logger_url) into $log"
lcm-logger "${logger_args[@]}" "$log" > /dev/null &
logger_pid=$!
pids+=("$logger_pid")
sleep 1  # let the logger join the group

echo "demo: 1. the bus: every message type, 100 messages at 100 Hz"
"$bin/sg-bus-check" receive --count 100 --timeout 5 "${url_args[@]}" > "$session.bus.txt" &
receiver_pid=$!
pids+=("$receiver_pid")
sleep 0.5
"$bin/sg-bus-check" send --count 100 --rate 100 "${url_args[@]}" > /dev/null
status=0
wait "$receiver_pid" || status=1
echo "   $(cat "$session.bus.txt")"
rm -f "$session.bus.txt"

frames=$(( seconds * 30 ))
echo "demo: 2. the cameras' calibration (the simulator's own: robot-guided calibration comes later)"
"$bin/sg-camera-sim" --snapshot "$session.pair.png" --snapshot-frame 60 \
  --calibration-out "$session.calibration.yaml" --log-level warn | sed 's/^/   /'

echo "demo: 3. cameras -> vision -> predictor -> viewer: the paper's motion at 30 Hz for $seconds s, occluded from 4 to 6 s"
"$bin/sg-vision" --calibration "$session.calibration.yaml" --log-level warn "${url_args[@]}" \
  > "$session.vision.txt" &
vision_pid=$!
"$bin/sg-predictor" --log-level warn "${url_args[@]}" > "$session.predictor.txt" &
predictor_pid=$!
"$bin/sg-viewer" --record "$session.view.avi" --no-window --calibration "$session.calibration.yaml" \
  --log-level warn "${url_args[@]}" > "$session.viewer.txt" &
viewer_pid=$!
pids+=("$vision_pid" "$predictor_pid" "$viewer_pid")
sleep 1
"$bin/sg-camera-sim" --frames "$frames" --occlusion 4:2 --log-level warn "${url_args[@]}" \
  | sed 's/^/   sg-camera-sim: /' || status=1
sleep 1
kill -INT "$vision_pid" "$predictor_pid" "$viewer_pid"
wait "$vision_pid" || status=1
wait "$predictor_pid" || status=1
wait "$viewer_pid" || status=1
pids=("$logger_pid")
echo "   sg-vision: $(cat "$session.vision.txt")"
echo "   sg-predictor: $(cat "$session.predictor.txt")"
echo "   sg-viewer: $(cat "$session.viewer.txt")"
rm -f "$session.vision.txt" "$session.predictor.txt" "$session.viewer.txt"

sleep 0.5
kill -INT "$logger_pid"
wait "$logger_pid" || true
pids=()

echo "demo: 4. what the log holds:"
"$bin/sg-bus-check" verify-log "$log" --count 100 | sed 's/^/   /' || status=1
if [ "$status" -ne 0 ]; then
  echo "demo: FAILED (log kept: $log)" >&2
  exit 1
fi
cat <<MSG
demo: done. The session log is $log
  the cameras' true calibration: $session.calibration.yaml
  a stereo pair as the cameras saw it: $session.pair.png
  the user interface, recorded: $session.view.avi (frame-to-utime: $session.view.avi.csv)
  replay it:   lcm-logplayer $log
  inspect it:  scripts/spy.sh (while replaying or during a demo)
MSG
