#!/usr/bin/env bash
# Configures the one sanitized build that scripts/test.sh --sanitize and scripts/fuzz.sh share
# (docs/fuzzing.md): clang, AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer's coverage
# instrumentation, -O1, the tests and the fuzz targets, no benchmarks, linked by lld (a test program
# with ASan's runtime links in a fraction of ld.bfd's time). Sharing it compiles the
# libraries once for both; CI runs the suite, then the fuzzers, from it.
#
#   scripts/sanitizer/configure.sh BUILD_DIR [CMAKE ARGS]
#
# Needs clang (scripts/bootstrap.sh --with-clang). -O1, as the sanitizers' authors advise:
# reports keep their lines, the build is shorter than -O3's; assert() stays on (no NDEBUG).
set -euo pipefail
cd "$(dirname "$0")/../.."
if [ $# -lt 1 ] || [ "$1" = -h ] || [ "$1" = --help ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  [ $# -ge 1 ] && exit 0 || exit 2
fi
build=$1
shift
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^SG_FUZZ:BOOL=ON' "$build/CMakeCache.txt"; then
  echo "sanitizer/configure.sh: $build/ is another kind of build; remove it or choose another" >&2
  exit 2
fi
cmake -S . -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -DSG_SANITIZE=ON -DSG_FUZZ=ON -DSG_BUILD_TESTS=ON \
  -DSG_BUILD_BENCH=OFF -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld \
  "$@" >/dev/null
