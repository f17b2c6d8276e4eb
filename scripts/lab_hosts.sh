#!/usr/bin/env bash
# Lab machines on one computer, for sg-lab's tests and trials (docs/lab.md): each host a network
# namespace with its own host name and an OpenSSH server, all on one bridge with private
# addresses, multicast routed over it. Root only. Run it inside `scripts/multicast.sh run` (or
# another private namespace) so the bridge never touches the machine's own network.
#
#   scripts/lab_hosts.sh up DIR [N] [BUILD]  hosts lab1..labN (default 3) at 10.231.0.11.. with an
#                                          sshd each; this namespace is 10.231.0.1 on bridge
#                                          sglab0. DIR gets the ssh key, each host's sshd files, a
#                                          project folder per host (DIR/labK: build/ linked to
#                                          BUILD, default this checkout's build/; config/ copied),
#                                          and ssh_options.yaml (the
#                                          lab file's ssh_options for these hosts)
#   scripts/lab_hosts.sh down DIR          stop the sshds, remove the namespaces and the bridge
#   scripts/lab_hosts.sh loss HOST PCT     drop PCT % of the UDP datagrams HOST receives
#                                          (iptables' statistic match; this kernel has no netem);
#                                          PCT 0 removes the rule
#   scripts/lab_hosts.sh exec DIR HOST CMD...  run CMD on HOST (its network and host name)
set -euo pipefail
cd "$(dirname "$0")/.."
project=$(pwd)
me=lab_hosts

die() { echo "$me: $*" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || die "needs root (network namespaces, an sshd per host)"

# Namespace names are global to the machine: each set of hosts is named after the network
# namespace it was made from (lab_trial.sh runs in one of its own), so two trials at once (a test
# and a developer's trial) never meet, and `down` removes only its own.
ns_prefix="sg-$(stat -L -c %i /proc/self/ns/net)-"
ns_of() { echo "$ns_prefix$1"; }
address_of() { echo "10.231.0.$((10 + ${1#lab}))"; }

# One host: a namespace joined to the bridge by a veth pair, loopback and multicast up.
make_host() {
  local name=$1 ns addr
  ns=$(ns_of "$name")
  addr=$(address_of "$name")
  ip netns add "$ns"
  ip link add "v-$name" type veth peer name eth0 netns "$ns"
  ip link set "v-$name" master sglab0 up
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "$addr/24" dev eth0
  ip -n "$ns" link set eth0 up multicast on
  ip -n "$ns" route add 224.0.0.0/4 dev eth0
}

# Its sshd: own host key, the lab key authorised for root, its own host name (a UTS namespace).
start_sshd() {
  local name=$1 dir=$2 ns addr
  ns=$(ns_of "$name")
  addr=$(address_of "$name")
  mkdir -p "$dir/$name.sshd"
  ssh-keygen -q -t ed25519 -N "" -f "$dir/$name.sshd/host_key" <<<y >/dev/null
  cat >"$dir/$name.sshd/sshd_config" <<CONF
ListenAddress $addr
HostKey $dir/$name.sshd/host_key
AuthorizedKeysFile $dir/authorized_keys
PermitRootLogin prohibit-password
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
PidFile $dir/$name.sshd/pid
AcceptEnv LANG
Subsystem sftp /usr/lib/openssh/sftp-server
# bash reads ~/.bashrc for an ssh command unless it is a nested shell: this machine's costs
# 0.5 s (pyenv) a call, which is not what sg-lab's figures are about
SetEnv SHLVL=1
CONF
  mkdir -p /run/sshd
  ip netns exec "$ns" unshare --uts sh -c "hostname $name && exec /usr/sbin/sshd -f $dir/$name.sshd/sshd_config -E $dir/$name.sshd/log"
  echo "$name $addr" >>"$dir/known_hosts.tmp"
}

# The host's project folder: this checkout's build and config, its own logs and files.
make_project() {
  local name=$1 dir=$2 build=$3
  mkdir -p "$dir/$name"
  ln -sfn "$build" "$dir/$name/build"
  mkdir -p "$dir/$name/config"
  cp "$project/config/stereograsp.yaml" "$dir/$name/config/"
}

up() {
  local dir=$1 n=${2:-3} build
  build=$(cd "${3:-$project/build}" && pwd)
  command -v /usr/sbin/sshd >/dev/null || die "no /usr/sbin/sshd (scripts/bootstrap.sh installs openssh-server)"
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  [ -e "$dir/lab_key" ] || ssh-keygen -q -t ed25519 -N "" -f "$dir/lab_key"
  cp "$dir/lab_key.pub" "$dir/authorized_keys"
  ip link add sglab0 type bridge
  ip addr add 10.231.0.1/24 dev sglab0
  ip link set sglab0 up multicast on
  ip route replace 224.0.0.0/4 dev sglab0
  rm -f "$dir/known_hosts.tmp"
  for k in $(seq 1 "$n"); do
    make_host "lab$k"
    start_sshd "lab$k" "$dir"
    make_project "lab$k" "$dir" "$build"
  done
  cat >"$dir/ssh_options.yaml" <<YAML
[-i, $dir/lab_key, -o, StrictHostKeyChecking=no, -o, UserKnownHostsFile=/dev/null, -o, LogLevel=ERROR]
YAML
  for k in $(seq 1 "$n"); do  # every sshd answers before we return
    for _ in $(seq 1 50); do
      ssh -i "$dir/lab_key" -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null \
        -o LogLevel=ERROR -o BatchMode=yes -o ConnectTimeout=2 "root@$(address_of "lab$k")" true \
        2>/dev/null && break
      sleep 0.1
    done
  done
  echo "$me: $n hosts up: $(for k in $(seq 1 "$n"); do printf 'lab%s=%s ' "$k" "$(address_of "lab$k")"; done)"
}

down() {
  local dir=$1
  for pidfile in "$dir"/lab*.sshd/pid; do
    [ -e "$pidfile" ] && kill "$(cat "$pidfile")" 2>/dev/null || true
  done
  for ns in $(ip netns list | awk -v p="$ns_prefix" 'index($1, p) == 1 {print $1}'); do
    ip netns pids "$ns" | xargs -r kill -9 2>/dev/null || true
    ip netns del "$ns"
  done
  ip link del sglab0 2>/dev/null || true
}

loss() {
  local name=$1 pct=$2 ns
  ns=$(ns_of "$name")
  ip netns exec "$ns" iptables -F INPUT
  [ "$pct" = 0 ] && return 0
  ip netns exec "$ns" iptables -A INPUT -p udp -m statistic --mode random \
    --probability "$(awk -v p="$pct" 'BEGIN { printf "%.4f", p / 100 }')" -j DROP
}

case "${1:-}" in
  up) shift; up "$@" ;;
  down) shift; down "$@" ;;
  loss) shift; loss "$@" ;;
  exec)  # in the host's sshd's namespaces: its network and its host name
    shift; dir=$1 name=$2; shift 2
    exec nsenter -t "$(cat "$dir/$name.sshd/pid")" -n -u "$@" ;;
  *) sed -n '2,20p' "$0" >&2; exit 2 ;;
esac
