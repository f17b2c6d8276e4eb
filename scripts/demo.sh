#!/usr/bin/env bash
# The most complete loop that runs on this machine without hardware, recorded by lcm-logger.
#
#   scripts/demo.sh [--seconds N] [--tag NAME]
#
# Today (foundation): every stereograsp message type crosses the real LCM bus between separate
# processes (sg-bus-check send -> sg-bus-check receive) while the stock lcm-logger records the
# session into logs/; the log is then checked message by message. Each later part of the system
# (camera simulator, vision, predictor, arm, grasping) joins this loop as it lands.
#
# The bus is LCM's default (or $LCM_DEFAULT_URL), so `scripts/spy.sh` in another terminal shows
# the channels while the demo runs.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${DEMO_SECONDS:-10}
tag=demo
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift ;;
    --tag) tag="$2"; shift ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

scripts/bootstrap.sh
if ! scripts/multicast.sh setup; then
  echo "demo: no multicast here; running the demo in a private network namespace" >&2
  exec scripts/multicast.sh run "$0" --seconds "$seconds" --tag "$tag"
fi

bin=build/bin
mkdir -p logs
log="logs/$(date +%Y%m%d-%H%M%S)-$tag.lcmlog"
url_args=()
[ -n "${LCM_DEFAULT_URL:-}" ] && url_args=(--lcm-url "$LCM_DEFAULT_URL")
logger_url=${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}

pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; }
trap cleanup EXIT

echo "demo: recording the bus ($logger_url) into $log"
lcm-logger --lcm-url="$logger_url" --quiet "$log" > /dev/null &
logger_pid=$!
pids+=("$logger_pid")
"$bin/sg-bus-check" receive --timeout 3 "${url_args[@]}" > logs/.demo-receive.txt &
receiver_pid=$!
pids+=("$receiver_pid")
sleep 1  # let the logger and the receiver join the group

echo "demo: sending every message type at 100 Hz for $seconds s (watch it: scripts/spy.sh)"
sent=$("$bin/sg-bus-check" send --count 0 --rate 100 --duration "$seconds" "${url_args[@]}")
echo "demo: $sent"
count=$(echo "$sent" | sed -n 's/^sent \([0-9]*\) .*/\1/p')
status=0
wait "$receiver_pid" || status=$?
grep -q "^received $count " logs/.demo-receive.txt || status=1
sleep 0.5
kill -INT "$logger_pid"
wait "$logger_pid" || true
pids=()

echo "demo: receiver: $(cat logs/.demo-receive.txt)"
rm -f logs/.demo-receive.txt
echo "demo: checking the log message by message:"
"$bin/sg-bus-check" verify-log "$log" --count "$count" > logs/.demo-verify.txt || status=1
sed 's/^/  /' logs/.demo-verify.txt
rm -f logs/.demo-verify.txt

if [ "$status" -ne 0 ]; then
  echo "demo: FAILED: messages were lost or corrupted (log kept: $log)" >&2
  exit 1
fi
cat <<MSG
demo: done. The session log is $log
  replay it:   lcm-logplayer $log
  inspect it:  scripts/spy.sh (while replaying), or lcm-logplayer-gui $log
MSG
