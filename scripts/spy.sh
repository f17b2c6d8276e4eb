#!/usr/bin/env bash
# Starts lcm-spy with the stereograsp types on its CLASSPATH, so it decodes every channel.
# Arguments go to lcm-spy (e.g. scripts/spy.sh --lcm-url='udpm://239.255.76.67:7667?ttl=1').
# Needs a display; on a machine without one: xvfb-run scripts/spy.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

jar=build/lcmtypes/stereograsp_lcmtypes.jar
[ -f "$jar" ] || scripts/bootstrap.sh
if [ -z "${DISPLAY:-}" ]; then
  echo "spy.sh: lcm-spy opens a window and DISPLAY is not set (try: xvfb-run scripts/spy.sh)" >&2
  exit 1
fi
export CLASSPATH="$PWD/$jar${CLASSPATH:+:$CLASSPATH}"
# Debian's lcm-spy passes -Xincgc, which Java 17 rejects.
export JDK_JAVA_OPTIONS="${JDK_JAVA_OPTIONS:-} -XX:+IgnoreUnrecognizedVMOptions"
exec lcm-spy "$@"
