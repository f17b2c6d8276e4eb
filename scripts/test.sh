#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test. Exits non-zero on any failure.
# Arguments go to ctest (e.g. scripts/test.sh -R Config).
#
# The tests run in a private network namespace (scripts/multicast.sh run), so their multicast
# never leaves the machine and never meets a running system's bus.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/bootstrap.sh
jobs=$(nproc)
scripts/multicast.sh run ctest --test-dir build --output-on-failure -j "$jobs" "$@"
