#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test. Exits non-zero on any failure.
# Arguments go to ctest (e.g. scripts/test.sh -R Config).
#
#   scripts/test.sh [CTEST ARGS]             build/ and every test
#   scripts/test.sh --sanitize [CTEST ARGS]  the same suite built with clang, AddressSanitizer
#                                            and UndefinedBehaviorSanitizer in build-sanitize/
#                                            (no benchmarks; the fuzz targets share the build);
#                                            any sanitizer report, in a test or in a process it
#                                            starts, fails the run (docs/fuzzing.md)
#                                            SG_SANITIZE_BUILD: another build folder;
#                                            SG_SANITIZE_TARGETS: only those targets and their
#                                            tests
#
# The tests run in a private network namespace (scripts/multicast.sh run), so their multicast
# never leaves the machine and never meets a running system's bus.
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc)

if [ "${1:-}" != "--sanitize" ]; then
  scripts/bootstrap.sh
  scripts/multicast.sh run ctest --test-dir build --output-on-failure -j "$jobs" "$@"
  exit 0
fi
shift

# ---- --sanitize ----
scripts/bootstrap.sh --no-build --with-clang
build=${SG_SANITIZE_BUILD:-build-sanitize}
scripts/sanitizer/configure.sh "$build"
# SG_SANITIZE_TARGETS builds only those targets and runs only their tests; gtest_discover_tests
# lists each unbuilt test program as NAME_NOT_BUILT.
targets=()
skip=()
if [ -n "${SG_SANITIZE_TARGETS:-}" ]; then
  read -r -d "" -a names <<<"$SG_SANITIZE_TARGETS" || true  # every line
  targets=(--target "${names[@]}")
  skip=(-E '_NOT_BUILT$')
fi
cmake --build "$build" -j "$jobs" "${targets[@]}"

# Every report also goes to a file (log_path), so a report in a process a test starts fails the
# run even when the test only expected that process to exit non-zero.
reports="$(cd "$build" && pwd)/sanitizer-reports"
rm -rf "$reports" && mkdir -p "$reports"
supp="$PWD/scripts/sanitizer"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:detect_stack_use_after_return=0:strict_string_checks=1:check_initialization_order=1:log_path=$reports/asan"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$reports/ubsan"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"

status=0
scripts/multicast.sh run ctest --test-dir "$build" --output-on-failure -j "$jobs" "${skip[@]}" \
  "$@" || status=$?

if compgen -G "$reports/*" >/dev/null; then
  echo "test.sh --sanitize: sanitizer reports:" >&2
  for f in "$reports"/*; do
    echo "==== $f" >&2
    cat "$f" >&2
  done
  status=1
fi
[ "$status" -eq 0 ] && echo "test.sh --sanitize: every test passed, no sanitizer report"
exit "$status"
