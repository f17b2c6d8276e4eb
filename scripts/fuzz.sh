#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang with ASan and UBSan) and runs each for a while.
# They share the sanitized build of scripts/test.sh --sanitize (scripts/sanitizer/configure.sh).
# Exits non-zero when any target crashes, fails one of its checks, or a sanitizer reports.
#
#   scripts/fuzz.sh SECONDS [TARGET...]   run each target (all by default) for SECONDS
#   scripts/fuzz.sh --list                the targets
#   scripts/fuzz.sh -h | --help
#
# Environment: SG_FUZZ_BUILD (default build-sanitize), SG_FUZZ_JOBS (targets run at once,
# default 1).
#
# Each target starts from a copy of its committed seeds (fuzz/corpus/NAME/) in
# build-sanitize/corpus/NAME/, which keeps what the run found (copy new inputs back with care:
# the committed corpus should stay small). A crashing input is kept in
# build-sanitize/artifacts/NAME/ and the fuzzer's output in build-sanitize/logs/NAME.log;
# reproduce with
#   build-sanitize/fuzz/NAME_fuzz build-sanitize/artifacts/NAME/crash-...
# See docs/fuzzing.md.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; }
targets_all() { for f in fuzz/*_fuzz.cpp; do basename "$f" _fuzz.cpp; done; }

case "${1:-}" in
  -h|--help) usage; exit 0 ;;
  --list) targets_all; exit 0 ;;
  ''|*[!0-9]*) echo "fuzz.sh: the first argument is SECONDS (see --help)" >&2; exit 2 ;;
esac
seconds=$1
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || mapfile -t targets < <(targets_all)
for t in "${targets[@]}"; do
  [ -f "fuzz/${t}_fuzz.cpp" ] || { echo "fuzz.sh: no target '$t' (see --list)" >&2; exit 2; }
done

build=${SG_FUZZ_BUILD:-build-sanitize}
jobs=${SG_FUZZ_JOBS:-1}

scripts/bootstrap.sh --no-build --with-clang
scripts/sanitizer/configure.sh "$build"
cmake --build "$build" -j "$(nproc)" --target "${targets[@]/%/_fuzz}"

supp="$PWD/scripts/sanitizer"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"

# run_one NAME: one target for $seconds; its log in $build/logs/NAME.log.
run_one() {
  local name=$1
  local corpus="$build/corpus/$name" artifacts="$build/artifacts/$name"
  mkdir -p "$corpus" "$artifacts" "$build/logs"
  touch "$build/logs/$name.start"  # crashes counted are those newer than this
  [ -d "fuzz/corpus/$name" ] && cp -n fuzz/corpus/"$name"/* "$corpus"/ 2>/dev/null || true
  local status=0
  "$build/fuzz/${name}_fuzz" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=25 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" \
    >"$build/logs/$name.log" 2>&1 || status=$?
  echo "$status" >"$build/logs/$name.status"
}

echo "fuzz.sh: ${#targets[@]} target(s), ${seconds} s each, $jobs at a time"
running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait -n || true; running=$((running - 1)); fi
done
wait

# The table: runs and execs/s from libFuzzer's final stats, coverage from its last status line.
failed=0
printf '%-16s %12s %10s %8s %8s  %s\n' target runs exec/s cov crashes result
for t in "${targets[@]}"; do
  log="$build/logs/$t.log"
  status=$(cat "$build/logs/$t.status")
  # (|| true: a target that failed on a seed printed no statistics)
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1 || true)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1 || true)
  cov=$({ grep -o 'cov: [0-9]*' "$log" || true; } | tail -n 1 | cut -d' ' -f2)
  crashes=$(find "$build/artifacts/$t" -type f -newer "$build/logs/$t.start" | wc -l)
  reports=$(grep -c -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|fuzz check failed' "$log" || true)
  result=ok
  if [ "$status" -ne 0 ] || [ "$reports" -gt 0 ]; then
    result="FAILED (exit $status; see $log)"
    failed=1
  fi
  printf '%-16s %12s %10s %8s %8s  %s\n' "$t" "${runs:-?}" "${speed:-?}" "${cov:-?}" "$crashes" "$result"
done
if [ "$failed" -ne 0 ]; then
  # What each failed target reported, so a log that is gone with its machine (CI) still says why,
  # and the crashing input itself (base64, up to 8 KiB) so it can be reproduced elsewhere.
  for t in "${targets[@]}"; do
    log="$build/logs/$t.log"
    grep -q -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|fuzz check failed' \
      "$log" || [ "$(cat "$build/logs/$t.status")" -ne 0 ] || continue
    echo "fuzz.sh: $t's report:" >&2
    grep -m 1 -B 2 -A 12 -E 'ERROR: |runtime error:|fuzz check failed' "$log" >&2 || tail -n 15 "$log" >&2
    find "$build/artifacts/$t" -type f -newer "$build/logs/$t.start" | head -n 1 | while read -r input; do
      echo "fuzz.sh: $input, base64:" >&2
      head -c 8192 "$input" | base64 >&2
    done
  done
  echo "fuzz.sh: a target failed; crashing inputs are in $build/artifacts/" >&2
  exit 1
fi
