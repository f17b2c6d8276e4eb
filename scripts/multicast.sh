#!/usr/bin/env bash
# Makes LCM's UDP multicast usable on this host.
#
#   scripts/multicast.sh [setup]   ensure a route for 224.0.0.0/4 exists; as root on a host with
#                                  only loopback, add one on lo (nothing is changed on a host that
#                                  already routes multicast, e.g. one with a default route)
#   scripts/multicast.sh check     exit 0 when multicast is routable here, 1 otherwise
#   scripts/multicast.sh run CMD…  run CMD in a private network namespace whose loopback carries
#                                  multicast (root: unshare -n; otherwise unshare -rn). Nothing it
#                                  sends can leave the machine or reach other processes' buses.
#                                  Falls back to `setup` and the host network if namespaces are
#                                  not allowed here.
set -euo pipefail

group=239.255.76.67   # LCM's default group

check() { ip route get "$group" >/dev/null 2>&1; }

setup() {
  if check; then
    echo "multicast: routable here ($(ip route get "$group" | head -n 1 | sed 's/ *$//'))"
    return 0
  fi
  if [ "$(id -u)" -eq 0 ]; then
    ip link set lo multicast on
    ip route replace 224.0.0.0/4 dev lo
    echo "multicast: added a route for 224.0.0.0/4 on lo"
  else
    cat >&2 <<MSG
multicast: no route for 224.0.0.0/4 and not root. Either, as root:
  ip link set lo multicast on; ip route replace 224.0.0.0/4 dev lo
or run the command in a private namespace:
  scripts/multicast.sh run COMMAND
MSG
    return 1
  fi
}

inside='ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec "$@"'

run() {
  if [ $# -eq 0 ]; then echo "multicast.sh run: no command given" >&2; exit 2; fi
  local flags=-n
  [ "$(id -u)" -eq 0 ] || flags=-rn
  if unshare "$flags" true 2>/dev/null; then
    exec unshare "$flags" sh -c "$inside" sh "$@"
  fi
  echo "multicast: network namespaces are not allowed here; using the host network" >&2
  setup
  exec "$@"
}

case "${1:-setup}" in
  setup) setup ;;
  check) check ;;
  run) shift; run "$@" ;;
  -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//' ;;
  *) echo "multicast.sh: unknown command '$1' (see --help)" >&2; exit 2 ;;
esac
