#!/usr/bin/env bash
# Issue 17's live grasps: N grasps of the moving ball through the real processes, after one
# robot-guided calibration, held or not by the simulator's truth, against the in-process trials
# of build/bin/grasp_success.
#
#   scripts/live_grasps.sh [--grasps N] [--jobs J] [--seed S] [--out DIR] [--warmup S]
#                          [--grasp-window S] [--rate HZ] [--only K,K...] [--calibration FILE]
#                          [--true-calibration] [--coefficients FILE] [--report failed|all|none]
#                          [--no-record] [--build-dir DIR]
#
# Once: the robot-guided calibration (sg-c550-sim --holding, sg-arm-driver, sg-camera-sim,
# sg-vision, sg-calibrate robot, as scripts/demo.sh does) and the predictor's coefficients
# (sg-predictor train on the paper's circle). Then each grasp, in a private network namespace of
# its own (scripts/multicast.sh run), --jobs at a time: fresh sg-c550-sim on a pseudo-terminal,
# sg-arm-driver, sg-vision with the calibration, sg-predictor, sg-grasp, and sg-camera-sim filming
# the ball on a path drawn like bench/grasp_success.cpp's draw_trial: phase uniform, circle radius
# 0.10-0.15 m, 0.5-2 rpm, Y drift 0-0.01 m/s; the grasp command at a time drawn in
# [warmup, warmup + window) from the cameras' start, and a total occlusion from 1 s before it,
# 3-4 s long, covering the close. `sg-grasp-ctl track` 3 s after the cameras start, then
# `sg-grasp-ctl grasp --wait` (asked again on a refusal, as demo.sh does); held or not from the
# simulator's truth (the CLOSE line of sg-c550-sim, and SIM_ARM_STATE after the lift) and
# sg-grasp's own verdict. lcm-logger records each grasp (all but the images) into its folder;
# sg-report runs on the failed ones.
#
# Defaults are the in-process trials' (grasp_success: 40 s warm-up, 20 s window, 4 Hz frames),
# so the two are comparable; a shorter --warmup saves time but gives the predictor less to learn
# from. The draws come from --seed and the grasp's index alone (a SHA-256 of both): grasp K of
# seed S is the same path, occlusion and times on every run, and `--seed S --only K` re-runs it
# (with --calibration DIR/calibration.yaml --coefficients DIR/coefficients.yaml to skip the
# calibration). The real processes run in real time, so the noise, the frame times and the
# controller's delays differ from run to run.
#
# Writes to --out (default logs/DATE-live-grasps): results.tsv (a row a grasp: its draws, held,
# sg-grasp's verdict, the miss distance at the CLOSE, frames dropped, ...), summary.md (the
# table, held/N with its 95% Wilson interval, miss p50/p95/max, wall time), and per grasp
# grasp-K/ with its config.yaml (the draws as sg-camera-sim and sg-c550-sim read them), every
# process's output and session.lcmlog. Prints a line per grasp and the summary.
#
# Exit 0 when every grasp ran to a verdict (held or not), 1 when one could not run (a process
# died, no CLOSE and no verdict from sg-grasp-ctl), 2 on a usage error.
#
# Commands are signed (docs/security.md): $SG_LAB_KEY or ~/.config/stereograsp/lab.key, else a
# session key made by sg-keygen for the run (removed at the end).
# shellcheck disable=SC2015  # `A && B || die`: B is a test, never a failing command
# shellcheck disable=SC2154  # each grasp's variables come from its params.sh
set -euo pipefail
self=$(realpath "$0")
cd "$(dirname "$self")/.."

me=live_grasps
die() { echo "$me: $*" >&2; exit 1; }
usage_error() { echo "$me: $* (see --help)" >&2; exit 2; }
# The comment at the top, without its '#'.
help() {
  awk '/^# shellcheck/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' \
    "$self"
}

# ---- options ---------------------------------------------------------------------------------
grasps=20
jobs=2
seed=1
out=""
warmup=40
window=20
rate=4
only=""
calibration=""
true_calibration=0
coefficients=""
report=failed
record=1
build_dir=build
inside=""   # internal: calibrate or grasp (run inside a private network namespace)
inside_args=()

parse_options() {
  while [ $# -gt 0 ]; do
    case "$1" in
      --grasps|--jobs|--seed|--out|--warmup|--grasp-window|--rate|--only|--calibration|\
      --coefficients|--report|--build-dir|--inside)
        [ $# -ge 2 ] || usage_error "$1 needs a value" ;;
    esac
    case "$1" in
      --grasps) grasps="$2"; shift ;;
      --jobs) jobs="$2"; shift ;;
      --seed) seed="$2"; shift ;;
      --out) out="$2"; shift ;;
      --warmup) warmup="$2"; shift ;;
      --grasp-window) window="$2"; shift ;;
      --rate) rate="$2"; shift ;;
      --only) only="$2"; shift ;;
      --calibration) calibration="$2"; shift ;;
      --true-calibration) true_calibration=1 ;;
      --coefficients) coefficients="$2"; shift ;;
      --report) report="$2"; shift ;;
      --no-record) record=0 ;;
      --build-dir) build_dir="$2"; shift ;;
      --inside) inside="$2"; shift; shift; inside_args=("$@"); return ;;
      -h|--help) help; exit 0 ;;
      *) usage_error "unknown option '$1'" ;;
    esac
    shift
  done
}

is_uint() { [[ "$1" =~ ^[0-9]+$ ]]; }
is_number() { [[ "$1" =~ ^[0-9]+([.][0-9]*)?$ ]]; }

check_options() {
  is_uint "$grasps" && [ "$grasps" -ge 1 ] || usage_error "--grasps '$grasps': a count >= 1"
  is_uint "$jobs" && [ "$jobs" -ge 1 ] || usage_error "--jobs '$jobs': a count >= 1"
  is_uint "$seed" || usage_error "--seed '$seed': a non-negative integer"
  is_number "$warmup" || usage_error "--warmup '$warmup': seconds"
  is_number "$window" || usage_error "--grasp-window '$window': seconds"
  is_number "$rate" && awk -v r="$rate" 'BEGIN { exit !(r >= 1 && r <= 60) }' ||
    usage_error "--rate '$rate': frames per second in 1..60"
  awk -v w="$warmup" 'BEGIN { exit !(w >= 5) }' || usage_error "--warmup '$warmup': at least 5 s"
  [[ -z "$only" || "$only" =~ ^[0-9]+(,[0-9]+)*$ ]] || usage_error "--only '$only': K,K,..."
  case "$report" in failed|all|none) ;; *) usage_error "--report '$report': failed, all or none" ;;
  esac
  [ -z "$calibration" ] || [ -s "$calibration" ] || die "--calibration $calibration: no such file"
  [ -z "$coefficients" ] || [ -s "$coefficients" ] ||
    die "--coefficients $coefficients: no such file"
  return 0
}

# ---- helpers -----------------------------------------------------------------------------------
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.0f", b - a }'; }

# Runs a command in the background and waits for it: a signal's trap runs at once, not after the
# command (bash defers traps while a foreground command runs); stop_all ends it with the rest.
interruptible() {
  "$@" &
  local p=$!
  pids+=("$p")
  local status=0
  wait "$p" || status=$?
  unset 'pids[-1]'
  return "$status"
}

# Sleeps until the epoch time $1 (at once if it is past).
sleep_until() {
  local left
  left=$(awk -v t="$1" -v n="$(now)" 'BEGIN { d = t - n; printf "%.3f", (d > 0 ? d : 0) }')
  interruptible sleep "$left"
}

# A uniform draw in [0, 1) from the string $1: the first 52 bits of its SHA-256.
uniform() {
  local h
  h=$(printf '%s' "$1" | sha256sum | cut -c1-13)
  awk -v h="$((16#$h))" 'BEGIN { printf "%.9f", h / 4503599627370496 }'
}
# A 32-bit seed from the string $1.
seed32() { echo $((16#$(printf '%s' "$1" | sha256sum | cut -c1-8))); }

# The 95% Wilson score interval of $1 successes in $2, in percent: "LOW HIGH".
wilson() {
  awk -v k="$1" -v n="$2" 'BEGIN {
    z = 1.959964; p = k / n; d = 1 + z * z / n; c = (p + z * z / (2 * n)) / d
    h = z * sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    lo = c - h; hi = c + h; if (lo < 0) lo = 0; if (hi > 1) hi = 1
    printf "%.1f %.1f", 100 * lo, 100 * hi }'
}

# Percentile $1 (0..1) of the numbers on stdin ("-" when there are none).
percentile() {
  sort -g | awk -v q="$1" '{ v[n++] = $1 } END {
    if (n == 0) { print "-"; exit } k = q * (n - 1); i = int(k)
    x = (i + 1 < n) ? v[i] + (k - i) * (v[i + 1] - v[i]) : v[n - 1]; printf "%.1f", x }'
}

# ---- inside a namespace: the processes ------------------------------------------------------
pids=()
stop_all() {
  local p
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for _ in $(seq 30); do
    local alive=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" -eq 0 ] && break
    sleep 0.1
  done
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  pids=()
}

wait_for_file() {
  for _ in $(seq 100); do [ -e "$1" ] && return 0; sleep 0.1; done
  return 1
}

start_logger() {
  [ "$record" -eq 1 ] || return 0
  lcm-logger --lcm-url='udpm://239.255.76.67:7667?ttl=0' --quiet -v -c 'CAMERA_.*' "$1" \
    > /dev/null 2>&1 &
  pids+=($!)
}

# The robot-guided calibration into $1 (its processes' output under $2).
inside_calibrate() {
  local cal=$1 dir=$2 bin=$build_dir/bin
  trap stop_all EXIT
  trap 'exit 130' INT TERM
  mkdir -p "$dir"
  "$bin/sg-c550-sim" --link "$dir/c550" --holding --log-level warn > "$dir/c550.txt" 2>&1 &
  pids+=($!)
  wait_for_file "$dir/c550" || die "calibration: sg-c550-sim made no pseudo-terminal"
  "$bin/sg-arm-driver" --device "$dir/c550" --log-level warn > "$dir/driver.txt" 2>&1 &
  pids+=($!)
  "$bin/sg-camera-sim" --log-level warn > "$dir/cameras.txt" 2>&1 &
  pids+=($!)
  "$bin/sg-vision" --log-level warn > "$dir/vision.txt" 2>&1 &
  pids+=($!)
  local status=0
  "$bin/sg-calibrate" robot --out "$cal" --log-level warn > "$dir/calibrate.txt" 2>&1 || status=$?
  sed 's/^/   /' "$dir/calibrate.txt"
  [ "$status" -eq 0 ] && [ -s "$cal" ] ||
    die "the robot-guided calibration failed (sg-calibrate exit $status; see $dir/)"
}

# Runs sg-grasp-ctl grasp --wait, asking again on a refusal (exit 4); prints its exit status.
ask_grasp() {
  local bin=$1 log=$2 status=1
  for attempt in 1 2 3 4 5; do
    set +e
    interruptible "$bin/sg-grasp-ctl" grasp --wait --timeout 40 >> "$log" 2>&1
    status=$?
    set -e
    echo "attempt $attempt: exit $status at $(now)" >> "$log"
    [ "$status" -eq 4 ] || break
    interruptible sleep 1
  done
  echo "$status"
}

# One grasp: $1 its folder (config.yaml and params there), inside its own namespace.
inside_grasp() {
  local dir=$1 bin=$build_dir/bin
  # shellcheck source=/dev/null
  . "$dir/params.sh"
  trap stop_all EXIT
  trap 'exit 130' INT TERM
  start_logger "$dir/session.lcmlog"
  "$bin/sg-c550-sim" --config "$dir/config.yaml" --link "$dir/c550" \
    --log-commands "$dir/c550.tsv" > "$dir/c550.txt" 2>&1 &
  pids+=($!)
  wait_for_file "$dir/c550" || die "grasp $index: sg-c550-sim made no pseudo-terminal"
  "$bin/sg-arm-driver" --device "$dir/c550" --log-level warn > "$dir/driver.txt" 2>&1 &
  pids+=($!)
  "$bin/sg-vision" --calibration "$calibration" --log-level warn > "$dir/vision.txt" 2>&1 &
  pids+=($!)
  "$bin/sg-predictor" --coefficients "$coefficients" --log-level warn \
    > "$dir/predictor.txt" 2>&1 &
  pids+=($!)
  "$bin/sg-grasp" > "$dir/grasp.txt" 2>&1 &
  pids+=($!)
  sleep 1  # every process on the bus before the first frame
  local start
  start=$(now)
  "$bin/sg-camera-sim" --config "$dir/config.yaml" --occlusion "$occlusion_start:$occlusion" \
    --log-level warn > "$dir/cameras.txt" 2>&1 &
  local cameras=$!
  pids+=("$cameras")
  echo "cameras started at $start" > "$dir/ctl.txt"
  sleep_until "$(awk -v s="$start" 'BEGIN { printf "%.3f", s + 3 }')"
  local tracked=0
  for _ in 1 2 3 4 5; do
    if interruptible "$bin/sg-grasp-ctl" track >> "$dir/ctl.txt" 2>&1; then tracked=1; break; fi
    interruptible sleep 1
  done
  [ "$tracked" -eq 1 ] || echo "track: never accepted" >> "$dir/ctl.txt"
  sleep_until "$(awk -v s="$start" -v g="$grasp_time" 'BEGIN { printf "%.3f", s + g }')"
  echo "grasp asked at $(now) ($(elapsed "$start") s after the cameras started)" >> "$dir/ctl.txt"
  ask_grasp "$bin" "$dir/ctl.txt" > "$dir/ctl.status"
  interruptible sleep 1  # the lift's last SIM_ARM_STATE into the log
  # The cameras' own count of frames dropped is printed when they stop: stop them first.
  kill -INT "$cameras" 2>/dev/null || true
  wait "$cameras" 2>/dev/null || true
  stop_all
}

# ---- outside: drawing, running, judging -----------------------------------------------------

# Draws grasp $1 of the seed and writes its folder $2: params.sh and config.yaml.
draw_grasp() {
  local k=$1 dir=$2 key="live_grasps/$seed/$1"
  local scen_seed c550_seed phase radius rpm drift grasp_time occlusion occlusion_start
  scen_seed=$(seed32 "$key/scenario")
  c550_seed=$(seed32 "$key/c550")
  phase=$(awk -v u="$(uniform "$key/phase")" 'BEGIN { printf "%.3f", 360 * u }')
  radius=$(awk -v u="$(uniform "$key/radius")" 'BEGIN { printf "%.4f", 0.10 + 0.05 * u }')
  rpm=$(awk -v u="$(uniform "$key/rpm")" 'BEGIN { printf "%.4f", 0.5 + 1.5 * u }')
  drift=$(awk -v u="$(uniform "$key/drift")" 'BEGIN { printf "%.5f", 0.01 * u }')
  grasp_time=$(awk -v u="$(uniform "$key/grasp")" -v w="$warmup" -v g="$window" \
    'BEGIN { printf "%.2f", w + g * u }')
  occlusion=$(awk -v u="$(uniform "$key/occlusion")" 'BEGIN { printf "%.2f", 3 + u }')
  occlusion_start=$(awk -v g="$grasp_time" 'BEGIN { printf "%.2f", g - 1 }')
  mkdir -p "$dir"
  cat > "$dir/params.sh" <<PARAMS
index=$k
seed=$seed
scenario_seed=$scen_seed
c550_seed=$c550_seed
phase_deg=$phase
radius=$radius
rpm=$rpm
drift_speed=$drift
grasp_time=$grasp_time
occlusion_start=$occlusion_start
occlusion=$occlusion
rate=$rate
calibration=$(realpath "$calibration_file")
coefficients=$(realpath "$coefficients_file")
PARAMS
  cat > "$dir/config.yaml" <<YAML
# scripts/live_grasps.sh --seed $seed, grasp $k: the ball's path and the controller's delays
# (read by sg-camera-sim and sg-c550-sim; every other setting is config/stereograsp.yaml's)
scenario:
  kind: paper
  radius: $radius
  rpm: $rpm
  drift_speed: $drift
  seed: $scen_seed
  phase_deg: $phase
camera_sim:
  rate_hz: $rate
c550_sim:
  seed: $c550_seed
YAML
}

# The TSV columns of results.tsv.
columns=(grasp scenario_seed phase_deg radius_m rpm drift_m_s c550_seed grasp_s occlusion_start_s
  occlusion_s held sg_grasp miss_mm close_after_grasp_s refusals frames_dropped track_lost wall_s
  note)

# Judges grasp folder $1 and prints its results.tsv row.
judge_grasp() {
  local dir=$1 bin=$build_dir/bin
  # shellcheck source=/dev/null
  . "$dir/params.sh"
  local close held="no" verdict miss="-" note="" refusals status after="-" dropped="-" lost
  status=$(cat "$dir/ctl.status" 2>/dev/null || echo 1)
  case "$status" in
    0) verdict=success ;;
    3) verdict=failed ;;
    4) verdict=refused ;;
    *) verdict="error($status)" ;;
  esac
  refusals=$(grep -c 'exit 4 at' "$dir/ctl.txt" 2>/dev/null || true)
  close=$(grep -o 'CLOSE at.*' "$dir/c550.txt" 2>/dev/null | tail -1 || true)
  if [ -n "$close" ]; then
    miss=$(echo "$close" | sed -n 's/.*centre \([0-9.]*\) mm away.*/\1/p')
    [ -n "$miss" ] || miss="-"
    case "$close" in *": held"*) held=yes ;; esac
    # When the CLOSE executed (sg-c550-sim's log line, local time; c550.tsv has when it was
    # received, one controller delay earlier) after the grasp command.
    local close_time asked
    close_time=$(grep 'CLOSE at' "$dir/c550.txt" | tail -1 | cut -d' ' -f1,2)
    close_time=$(date -d "$close_time" +%s.%N 2>/dev/null || true)
    asked=$(sed -n 's/^grasp asked at \([0-9.]*\).*/\1/p' "$dir/ctl.txt")
    [ -n "$close_time" ] && [ -n "$asked" ] &&
      after=$(awk -v c="$close_time" -v a="$asked" 'BEGIN { printf "%.1f", c - a }')
  else
    note="no CLOSE"
  fi
  # Held after the lift too, as the in-process trials judge it: the last SIM_ARM_STATE holds the
  # ball with the tool at least half the lift (0.15 m) above the CLOSE.
  if [ "$held" = yes ] && [ -s "$dir/session.lcmlog" ]; then
    local close_z last
    close_z=$(echo "$close" | sed -n 's/^CLOSE at ([^,]*, [^,]*, \([-0-9.]*\)).*/\1/p')
    last=$("$bin/sg-report" export "$dir/session.lcmlog" --channel SIM_ARM_STATE --csv 2>/dev/null |
      awk -F, -v z="${close_z:-0}" 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
        { h = $c["holding_object"]; up = $c["tool_position_2"] - z }
        END { print (h == 1 ? (up >= 0.075 ? "lifted" : "not lifted") : "dropped") }' || true)
    case "$last" in
      lifted|"") ;;
      *) held=no; note="${note:+$note; }held at the CLOSE, $last after" ;;
    esac
  fi
  dropped=$(sed -n 's/.*dropped \([0-9]*\) late.*/\1/p' "$dir/cameras.txt" | tail -1)
  [ -n "$dropped" ] || dropped="-"
  lost=$(cat "$dir/vision.txt" "$dir/predictor.txt" "$dir/grasp.txt" 2>/dev/null |
    grep -ci 'track lost' || true)
  local final
  final=$(grep -o 'outcome.*' "$dir/ctl.txt" 2>/dev/null | tail -1 | tr '\t' ' ' | cut -c1-160 ||
    true)
  [ "$verdict" = success ] || note="${note:+$note; }${final:-no GRASP_STATUS}"
  printf '%s\t' "$index" "$scenario_seed" "$phase_deg" "$radius" "$rpm" "$drift_speed" \
    "$c550_seed" "$grasp_time" "$occlusion_start" "$occlusion" "$held" "$verdict" "$miss" \
    "$after" "$refusals" "$dropped" "$lost" "$(cat "$dir/wall_s" 2>/dev/null || echo -)"
  printf '%s\n' "${note:--}"
}

run_grasp() {
  local k=$1 dir=$2 t0
  t0=$(now)
  local flags=(--build-dir "$build_dir")
  [ "$record" -eq 1 ] || flags+=(--no-record)
  scripts/multicast.sh run "$self" "${flags[@]}" --inside grasp "$dir" > "$dir/run.txt" 2>&1 &
  local child=$!
  # A background job ignores SIGINT: the outer script's clean-up sends TERM, passed on here.
  trap 'kill -TERM "$child" 2>/dev/null; wait "$child" 2>/dev/null; exit 143' TERM
  wait "$child" || true
  trap - TERM
  elapsed "$t0" > "$dir/wall_s"
  judge_grasp "$dir" > "$dir/result.tsv"
  local good=0
  cut -f11,12 "$dir/result.tsv" | grep -q $'^yes\tsuccess$' && good=1
  if [ "$report" = all ] || { [ "$report" = failed ] && [ "$good" -eq 0 ]; }; then
    [ -s "$dir/session.lcmlog" ] &&
      "$build_dir/bin/sg-report" "$dir/session.lcmlog" --no-plots --quiet \
        --out "$dir/report" > /dev/null 2>&1 || true
  fi
}

# The progress line of a finished grasp from its result.tsv.
progress_line() {
  awk -F'\t' -v n="$2" -v h="$3" -v d="$4" '{
    printf "%s: grasp %s (%d/%d done): %s, miss %s mm, sg-grasp %s, %s s%s  [held %d of %d]\n",
      "live_grasps", $1, d, n, ($11 == "yes" ? "HELD" : "NOT HELD"), $13, $12, $18,
      ($19 == "-" ? "" : " (" $19 ")"), h, d }' "$1"
}

sign_commands() {
  local default_key=${SG_LAB_KEY:-${HOME:-/nonexistent}/.config/stereograsp/lab.key}
  if [ -e "$default_key" ]; then
    export SG_LAB_KEY="$default_key"
    echo "$me: signing commands with the lab key $SG_LAB_KEY"
  else
    key_dir=$(mktemp -d)
    export SG_LAB_KEY="$key_dir/lab.key"
    "$build_dir/bin/sg-keygen" "$SG_LAB_KEY" > /dev/null
    echo "$me: no lab key at $default_key; signing with a session key (sg-keygen)"
  fi
}

prepare_calibration() {
  calibration_file="$out/calibration.yaml"
  if [ -n "$calibration" ]; then
    [ "$(realpath "$calibration")" = "$(realpath -m "$calibration_file")" ] ||
      cp "$calibration" "$calibration_file"
    echo "$me: calibration: $calibration (given)"
  elif [ "$true_calibration" -eq 1 ]; then
    "$build_dir/bin/sg-camera-sim" --calibration-out "$calibration_file" \
      --snapshot "$out/pair.png" --log-level warn > /dev/null
    echo "$me: calibration: the simulator's own cameras (--true-calibration)"
  else
    echo "$me: calibration, robot-guided: the arm carries the ball through a grid"
    local t0
    t0=$(now)
    scripts/multicast.sh run "$self" --build-dir "$build_dir" --inside calibrate \
      "$calibration_file" "$out/calibration" ||
      die "the robot-guided calibration failed (see $out/calibration/)"
    echo "$me: calibration done in $(elapsed "$t0") s: $calibration_file"
  fi
}

prepare_coefficients() {
  coefficients_file="$out/coefficients.yaml"
  if [ -n "$coefficients" ]; then
    [ "$(realpath "$coefficients")" = "$(realpath -m "$coefficients_file")" ] ||
      cp "$coefficients" "$coefficients_file"
    echo "$me: predictor coefficients: $coefficients_file (given: $coefficients)"
    return 0
  fi
  # Four minutes of the paper's circle at 4 Hz, t,x,y,z, with 1 mm of noise per axis (seeded), as
  # scripts/demo.sh trains them: what Burg's predictors start from (docs/prediction.md).
  awk 'function g() { return sqrt(-2 * log(1 - rand())) * cos(2 * pi * rand()) }
    BEGIN { srand(7); pi = atan2(0, -1); for (k = 0; k < 960; k++) { t = k * 0.25;
    a = 2 * pi * t / 60; printf "%.2f,%.6f,%.6f,%.6f\n", t, 0.45 + 0.15 * cos(a) + 0.001 * g(),
    0.15 * sin(a) + 0.001 * g(), 0.10 + 0.001 * g() } }' > "$out/circle.csv"
  "$build_dir/bin/sg-predictor" train "$out/circle.csv" --out "$coefficients_file" > /dev/null ||
    die "sg-predictor train failed"
  rm -f "$out/circle.csv"
  echo "$me: predictor coefficients: $coefficients_file (sg-predictor train, the paper's circle)"
}

summary() {
  local n=$1 held agree wall lo hi p50 p95 max pct
  held=$(awk -F'\t' 'NR > 1 && $11 == "yes"' "$out/results.tsv" | wc -l)
  agree=$(awk -F'\t' 'NR > 1 && (($11 == "yes") == ($12 == "success"))' "$out/results.tsv" | wc -l)
  read -r lo hi <<< "$(wilson "$held" "$n")"
  pct=$(awk -v h="$held" -v n="$n" 'BEGIN { printf "%.0f", 100 * h / n }')
  p50=$(awk -F'\t' 'NR > 1 && $13 != "-" { print $13 }' "$out/results.tsv" | percentile 0.5)
  p95=$(awk -F'\t' 'NR > 1 && $13 != "-" { print $13 }' "$out/results.tsv" | percentile 0.95)
  max=$(awk -F'\t' 'NR > 1 && $13 != "-" { print $13 }' "$out/results.tsv" | percentile 1)
  wall=$(elapsed "$run_start")
  {
    echo "# Live grasps: scripts/live_grasps.sh"
    echo
    echo "$(date -u +%Y-%m-%dT%H:%M:%SZ), $(hostname), $(nproc) cores; --seed $seed, $n grasps" \
      "($([ -n "$only" ] && echo "--only $only" || echo "grasps 0..$((n - 1))")), --jobs $jobs," \
      "--warmup $warmup s, --grasp-window $window s," \
      "--rate $rate Hz, calibration $calibration_source."
    echo
    echo "**held $held of $n** ($pct%, 95% Wilson interval $lo-$hi%);" \
      "sg-grasp's own verdict agrees in $agree of $n;" \
      "miss at the CLOSE p50 $p50 mm, p95 $p95 mm, max $max mm; wall time $wall s."
    echo
    printf '| %s ' "${columns[@]}"
    echo "|"
    printf '|---%.0s' "${columns[@]}"
    echo "|"
    awk -F'\t' 'NR > 1 { s = "|"; for (i = 1; i <= NF; ++i) s = s " " $i " |"; print s }' \
      "$out/results.tsv"
    echo
    echo "Re-run grasp K: \`scripts/live_grasps.sh --seed $seed --only K --warmup $warmup" \
      "--grasp-window $window --rate $rate --calibration $out/calibration.yaml" \
      "--coefficients $out/coefficients.yaml\`"
  } > "$out/summary.md"
  echo "$me: held $held of $n, 95% Wilson interval $lo-$hi%; sg-grasp agrees in $agree of $n;" \
    "miss p50 $p50 mm, p95 $p95 mm, max $max mm; $wall s"
  echo "$me: results: $out/results.tsv, $out/summary.md"
}

# Kills the running grasps (their own traps stop their processes) and the session key.
outer_cleanup() {
  local p
  for p in "${running[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${running[@]}"; do wait "$p" 2>/dev/null || true; done
  [ -z "$key_dir" ] || rm -rf "$key_dir"
}

main() {
  check_options
  for b in sg-c550-sim sg-arm-driver sg-camera-sim sg-vision sg-predictor sg-grasp sg-grasp-ctl \
           sg-calibrate sg-keygen sg-report; do
    [ -x "$build_dir/bin/$b" ] ||
      die "$build_dir/bin/$b not found: build first (scripts/bootstrap.sh)"
  done
  [ "$record" -eq 0 ] || command -v lcm-logger > /dev/null ||
    die "lcm-logger not found (scripts/bootstrap.sh installs it), or use --no-record"
  scripts/multicast.sh run true 2> /dev/null ||
    die "cannot run a private network namespace (scripts/multicast.sh run)"
  unshare -n true 2> /dev/null || unshare -rn true 2> /dev/null ||
    die "network namespaces are not allowed here: parallel grasps would share one bus"
  out=${out:-logs/$(date +%Y%m%d-%H%M%S)-live-grasps}
  mkdir -p "$out"
  run_start=$(now)
  key_dir=""
  running=()
  trap outer_cleanup EXIT
  trap 'echo "$me: interrupted" >&2; exit 130' INT TERM
  sign_commands
  calibration_source=$([ -n "$calibration" ] && echo "given ($calibration)" ||
    { [ "$true_calibration" -eq 1 ] && echo "the simulator's true cameras" || echo robot-guided; })
  prepare_calibration
  prepare_coefficients

  local indices=() k
  if [ -n "$only" ]; then IFS=, read -r -a indices <<< "$only"; else
    for ((k = 0; k < grasps; ++k)); do indices+=("$k"); done
  fi
  local n=${#indices[@]}
  echo "$me: $n grasps, $jobs at a time, seed $seed, warm-up $warmup s + up to $window s," \
    "$rate Hz frames; out: $out"
  for k in "${indices[@]}"; do draw_grasp "$k" "$out/grasp-$k"; done

  local next=0 done=0 held=0 status=0 p
  declare -A dir_of=()
  while [ "$done" -lt "$n" ]; do
    while [ "${#running[@]}" -lt "$jobs" ] && [ "$next" -lt "$n" ]; do
      k=${indices[$next]}
      # shellcheck source=/dev/null
      (. "$out/grasp-$k/params.sh"
       echo "$me: grasp $k started: r $radius m, $rpm rpm, drift $drift_speed m/s," \
         "phase $phase_deg deg, grasp at $grasp_time s, occluded $occlusion_start+$occlusion s")
      run_grasp "$k" "$out/grasp-$k" &
      running+=($!)
      dir_of[$!]="$out/grasp-$k"
      next=$((next + 1))
    done
    wait -n "${running[@]}" 2>/dev/null || true
    local still=()
    for p in "${running[@]}"; do
      if kill -0 "$p" 2>/dev/null; then still+=("$p"); continue; fi
      wait "$p" 2>/dev/null || true
      done=$((done + 1))
      local row=${dir_of[$p]}/result.tsv
      if [ -s "$row" ]; then
        [ "$(cut -f11 "$row")" = yes ] && held=$((held + 1))
        progress_line "$row" "$n" "$held" "$done"
        case "$(cut -f12 "$row")" in success|failed) ;; *) grep -q 'CLOSE' "${row%/*}/c550.txt" ||
          status=1 ;; esac
      else
        echo "$me: ${dir_of[$p]}: no result" >&2
        status=1
      fi
    done
    running=("${still[@]}")
  done
  (IFS=$'\t'; echo "${columns[*]}") > "$out/results.tsv"
  for k in "${indices[@]}"; do cat "$out/grasp-$k/result.tsv" 2>/dev/null || true; done \
    >> "$out/results.tsv"
  summary "$n"
  return "$status"
}

parse_options "$@"
case "$inside" in
  calibrate) inside_calibrate "${inside_args[@]}" ;;
  grasp) inside_grasp "${inside_args[@]}" ;;
  "") main ;;
  *) usage_error "--inside '$inside': calibrate or grasp" ;;
esac
