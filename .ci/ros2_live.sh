#!/usr/bin/env bash
# Your stack in the loop, proven with a real ROS 2 peer: deploy/ros2/follow_route.py (rclpy on
# Fast DDS, from PyPI's ROS wheels in target/rclpy-venv) drives the jet of
# scenarios/cone_in_path_jet.toml through `taxi-sim run --stack ros2`
# (ros2-client on RustDDS) in lockstep, inside a private network namespace
# (deploy/ros2/netns.sh). Five runs, each report checked: a whole route answered at every step,
# twice, the same to the step;
# a stack that goes silent (strict: stack_timeout, the time and topic named); one that commands
# NaN (stack_failed, the field named); no stack at all (the missing topics named).
#   deploy/ros2/netns.sh .ci/ros2_live.sh
set -euo pipefail
cd "$(dirname "$0")/.."
py=target/rclpy-venv/bin/python
bin=target/release/taxi-sim
maps=${TAXI_SIM_TEST_MAPS:-target/ci-maps}
out=target/ci-ros2
rm -rf "$out" && mkdir -p "$out"
export ROS_DOMAIN_ID=61 FASTDDS_DEFAULT_PROFILES_FILE=$PWD/deploy/ros2/fastdds_udp_buffers.xml
# The jet down a taxiway, a cone on the centreline until 60 s: the stack must stop short of it.
scenario=scenarios/cone_in_path_jet.toml

live() {  # live NAME [STACK ARGS...] -- [RUN ARGS...]
    local name=$1; shift
    local stack_args=()
    while [ $# -gt 0 ] && [ "$1" != -- ]; do stack_args+=("$1"); shift; done
    shift || true
    timeout 900 "$py" deploy/ros2/follow_route.py --corridor-half-width 2.5 --lookahead 20 "${stack_args[@]}" \
        > "$out/$name.stack.log" 2>&1 &
    local pid=$!
    local rc=0
    timeout 600 "$bin" run "$scenario" --stack ros2 --maps-dir "$maps" \
        --report "$out/$name.json" "$@" > "$out/$name.log" 2>&1 || rc=$?
    kill -INT "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    echo "$rc" > "$out/$name.rc"
    echo "[ros2] $name: taxi-sim exit $rc"; tail -n 4 "$out/$name.log" | sed 's/^/    /'
}

live whole
live again
live silent --stop-answering-at 3.0 -- --stack-timeout-s 2
live nan --nan-at 2.0
# No stack: the run must not start, and say which topics had no peer.
rc=0; timeout 60 "$bin" run "$scenario" --stack ros2 --maps-dir "$maps" \
    --discovery-timeout-s 3 > "$out/none.log" 2>&1 || rc=$?
echo "$rc" > "$out/none.rc"
echo "[ros2] none: taxi-sim exit $rc"; tail -n 2 "$out/none.log" | sed 's/^/    /'

python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
def report(n): return json.loads((out / f"{n}.json").read_text())
def rc(n): return int((out / f"{n}.rc").read_text())
bad = []
def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    ok or bad.append(what)
r = report("whole"); s = r["stack"]
check(r["end"] == "completed" and r["laps_completed"] == 1, f"whole: the route completed ({r['end']})")
check(s["steps"] > 300 and s["commands"] == s["steps"] and s["late"] == 0,
      f"whole: every one of {s['steps']} steps answered in time ({s['commands']} commands, {s['late']} late, {s['stale']} stale)")
check(len(r["contacts"]) == 0, "whole: no contact")
p = r["obstacles"][0]["passes"]
check(len(p) == 1 and p[0]["outcome"] == "stopped" and r["expectations_met"],
      f"whole: stopped short of the cone, then went on: every expectation held ({p})")
a = report("again")
check(a["sim_time_s"] == r["sim_time_s"] and a["obstacles"] == r["obstacles"] and a["stack"]["steps"] == s["steps"],
      f"again: the same run, step for step ({a['stack']['steps']} steps, lap {a['lap_times_s']} s)")
r = report("silent"); s = r["stack"]
check(r["end"] == "stack_timeout" and rc("silent") == 1, f"silent: ends stack_timeout ({r['end']}), exit 1")
check(s["first_late"] == [3.0, "/cmd_vel"] and s["commands"] == 30,
      f"silent: late first at t = 3.0 s on /cmd_vel ({s['first_late']}, {s['commands']} commands)")
r = report("nan"); s = r["stack"]
check(r["end"] == "stack_failed" and "twist.linear.x = NaN" in s.get("error", "")
      and "t = 2.000 s" in s.get("error", ""), f"nan: ends stack_failed naming the field and time ({s.get('error')})")
log = (out / "none.log").read_text()
check(rc("none") != 0 and "no subscriber of /velodyne_points" in log and "no publisher of /cmd_vel" in log,
      "none: refused, naming both missing topics")
sys.exit(1 if bad else 0)
PY
