#!/usr/bin/env bash
# Runs a command in a private network namespace where DDS peers find each other and nothing
# leaves the machine: loopback up, and a veth pair carrying multicast (RustDDS discovers only
# over multicast and does not use loopback locators; Fast DDS's localhost-only mode is not
# understood by it). Needs root or CAP_SYS_ADMIN (unshare -n).
#   deploy/ros2/netns.sh COMMAND [ARG...]
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 COMMAND [ARG...]" >&2; exit 2; }
if [ "${TAXI_SIM_NETNS:-}" != 1 ]; then
    exec env TAXI_SIM_NETNS=1 unshare -n "$0" "$@"
fi
ip link set lo up
ip link add v0 type veth peer name v1
ip addr add 10.61.0.1/24 dev v0
ip link set v1 up
ip link set v0 up mtu 65000
ip route add 224.0.0.0/4 dev v0
exec "$@"
