#!/usr/bin/env bash
# Your stack in the loop, proven with a real ROS 2 peer: deploy/ros2/follow_route.py (rclpy on
# Fast DDS, from PyPI's ROS wheels in target/rclpy-venv) drives the jet of
# scenarios/cone_in_path_jet.toml through `taxi-sim run --stack ros2`
# (ros2-client on RustDDS) in lockstep, inside a private network namespace
# (deploy/ros2/netns.sh). Nine runs and two small campaigns, each report checked: a whole route
# answered at every step; its first 20 s again, the simulator starting the stack itself
# (--stack-command) and the stack flooding ten junk commands a step (discarded); the
# hostile peers: a stack that goes silent (strict: stack_timeout, the time and topic named), one
# that commands NaN (stack_failed, the field named), one that stamps its commands with the
# revolution before (stale, then stack_timeout), one that answers once 3 s late (--lenient:
# held, counted, the run goes on; that run publishes /ground_truth/pose for tools, and a tool
# gets it at every step, while the other runs have no such topic), one that crashes (its status and last log line named), one
# that never subscribes, and no stack at all (the missing topics named); and a campaign of two
# variants run two jobs at a time on two ROS domains, then one job: the same records; and our own
# stack as a ROS 2 node (`taxi-sim stack`) giving the in-process report field for field on three
# scenarios; and Cyclone DDS (another DDS implementation, no ROS) reading the clock and the clouds.
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

# The same, the simulator starting and stopping the stack (`--stack-command`).
spawned() {  # spawned NAME [STACK ARGS...] -- [RUN ARGS...]
    local name=$1; shift
    local stack_args=()
    while [ $# -gt 0 ] && [ "$1" != -- ]; do stack_args+=("$1"); shift; done
    shift || true
    local rc=0
    timeout 600 "$bin" run "$scenario" --stack ros2 --maps-dir "$maps" --report "$out/$name.json" \
        --stack-command "$py deploy/ros2/follow_route.py --corridor-half-width 2.5 --lookahead 20 ${stack_args[*]}" \
        --stack-log "$out/$name.stack.log" "$@" > "$out/$name.log" 2>&1 || rc=$?
    echo "$rc" > "$out/$name.rc"
    echo "[ros2] $name: taxi-sim exit $rc"; tail -n 4 "$out/$name.log" | sed 's/^/    /'
}

live whole
spawned again --flood 10 -- --time-limit-s 20
live silent --stop-answering-at 3.0 -- --stack-timeout-s 2
live nan --nan-at 2.0
live wrong --wrong-stamp-from 3.0 -- --stack-timeout-s 2
live late --late-at 3.0 --late-by 3.0 --count-ground-truth -- --stack-timeout-s 2 --lenient --time-limit-s 8 --ros-ground-truth
spawned crash --crash-at 3.0
live deaf --no-subscribe -- --discovery-timeout-s 3
# Your stack in a campaign (scenarios/campaigns/your_stack.toml, two variants): two jobs at a
# time, each on a ROS domain of its own (62, 63), each run's stack started by the simulator; then
# one job. The records must be the same: no job heard another's.
for jobs in 2 1; do
    rc=0
    timeout 600 "$bin" campaign run scenarios/campaigns/your_stack.toml --out "$out/campaign-$jobs" \
        --maps-dir "$maps" --jobs "$jobs" --stack ros2 --ros-domain-id 62 \
        --stack-command "$py deploy/ros2/follow_route.py --corridor-half-width 2.5 --lookahead 20" \
        > "$out/campaign-$jobs.log" 2>&1 || rc=$?
    echo "$rc" > "$out/campaign-$jobs.rc"
    echo "[ros2] campaign, $jobs jobs: taxi-sim exit $rc"; tail -n 2 "$out/campaign-$jobs.log" | sed 's/^/    /'
done

# Our own stack over ROS 2 (`taxi-sim stack`, the simulator starting it) against the same node
# in the process (`run --stack node`): the straight road, the parking lot (one lap) and a traffic
# scenario must give the same report, every field but wall times.
for s in cone_in_path_jet parking_lot traffic_van_meets_nose; do
    rc=0
    timeout 600 "$bin" run "scenarios/$s.toml" --laps 1 --stack node --maps-dir "$maps" \
        --report "$out/node-$s.json" > "$out/node-$s.log" 2>&1 || rc=$?
    echo "$rc" > "$out/node-$s.rc"
    timeout 600 "$bin" run "scenarios/$s.toml" --laps 1 --stack ros2 --ros-domain-id 64 --maps-dir "$maps" \
        --report "$out/ours-$s.json" --stack-log "$out/ours-$s.stack.log" \
        --stack-command "$bin stack scenarios/$s.toml --laps 1 --maps-dir $maps" \
        > "$out/ours-$s.log" 2>&1 || rc=$?
    echo "$rc" > "$out/ours-$s.rc"
    echo "[ros2] our stack over ROS 2, $s: taxi-sim exit $rc"; tail -n 1 "$out/ours-$s.log" | sed 's/^/    /'
done

# A second DDS implementation, no ROS at all: Cyclone DDS (PyPI) reads the clock and every cloud
# of a 10 s run of our stack over ROS 2.
ROS_DOMAIN_ID=65 target/cyclone-venv/bin/python deploy/ros2/cyclone_listen.py --out "$out/cyclone.json" \
    --quiet-s 3 > "$out/cyclone.log" 2>&1 &
cyclone=$!
sleep 2
rc=0
timeout 300 "$bin" run "$scenario" --stack ros2 --ros-domain-id 65 --maps-dir "$maps" --time-limit-s 10 \
    --report "$out/cyclone-run.json" --stack-command "$bin stack $scenario --maps-dir $maps" \
    > "$out/cyclone-run.log" 2>&1 || rc=$?
wait "$cyclone" || true
echo "[ros2] Cyclone DDS listening: taxi-sim exit $rc"; tail -n 1 "$out/cyclone.log" | sed 's/^/    /'

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
whole = r
a = report("again")
check(a["stack"]["steps"] >= 200 and abs(a["sim_time_s"] - 20.0) < 0.02 and not a["contacts"],
      f"again: the first 20 s answered step for step ({a['stack']['steps']} steps, {a['end']})")
check("started the stack (pid " in (out / "again.log").read_text(), "again: the simulator started the stack")
check(a["stack"]["stale"] >= 10 and a["stack"]["commands"] == a["stack"]["steps"],
      f"again: {a['stack']['stale']} junk commands (10 a step, other times) discarded, every step answered")
r = report("silent"); s = r["stack"]
check(r["end"] == "stack_timeout" and rc("silent") == 1, f"silent: ends stack_timeout ({r['end']}), exit 1")
check(s["first_late"] == [3.0, "/cmd_vel"] and s["commands"] == 30,
      f"silent: late first at t = 3.0 s on /cmd_vel ({s['first_late']}, {s['commands']} commands)")
r = report("nan"); s = r["stack"]
check(r["end"] == "stack_failed" and "twist.linear.x = NaN" in s.get("error", "")
      and "t = 2.000 s" in s.get("error", ""), f"nan: ends stack_failed naming the field and time ({s.get('error')})")
r = report("wrong"); s = r["stack"]
check(r["end"] == "stack_timeout" and rc("wrong") == 1 and s["first_late"] == [3.0, "/cmd_vel"]
      and s["stale"] >= 1 and s["commands"] == 30,
      f"wrong: commands for the revolution before are stale ({s['stale']}), then stack_timeout at 3.0 s ({r['end']}, {s['first_late']})")
r = report("late"); s = r["stack"]
check(r["end"] == "timed_out" and s["late"] == 1 and s["first_late"] == [3.0, "/cmd_vel"]
      and s["stale"] >= 1 and s["commands"] == s["steps"] - 1 and not r["contacts"],
      f"late, lenient (3 s late, 2 s timeout): one step late at 3.0 s held and counted ({s['late']} late, {s['stale']} stale), the run went on to its 8 s limit ({r['end']})")
seen = lambda n: next((l for l in (out / f"{n}.stack.log").read_text().splitlines() if "topics seen:" in l), "")  # noqa: E731
count = [l for l in (out / "late.stack.log").read_text().splitlines() if "ground truth messages:" in l]
check("/ground_truth/pose" in seen("late") and count and int(count[0].split()[-1]) >= 70,
      f"ground truth: with --ros-ground-truth a tool gets /ground_truth/pose at every step ({count[0].split(': ', 1)[-1] if count else 'none'})")
check("/velodyne_points" in seen("whole") and "/ground_truth/pose" not in seen("whole"),
      "ground truth: without it the topic does not exist")
check(all(t in seen("whole") for t in ("/clock", "/tf", "/tf_static", "/odom", "/localization/pose", "/route", "/collision_model", "/map/level_0", "/map/level_1")),
      "whole: the stack's graph shows every topic of the contract (the offline map's two levels, the collision model...) 2 s in")
r = report("crash"); s = r["stack"]; e = s.get("error", "")
check(r["end"] == "stack_failed" and rc("crash") == 1 and "exited with status 3 at t = 3.000 s" in e
      and "crashing on purpose" in e, f"crash: stack_failed with its status, the time and its last log line ({e!r})")
log = (out / "deaf.log").read_text()
check(rc("deaf") != 0 and "no subscriber of /velodyne_points" in log and "no publisher of /cmd_vel" not in log,
      "deaf: refused, naming the cloud's missing subscriber only")
def records(d):
    rows = [json.loads(l) for l in (out / d / "results.jsonl").read_text().splitlines() if l.strip()]
    return sorted(({k: v for k, v in r.items() if "wall" not in k} for r in rows), key=lambda r: r["index"])
two, one = records("campaign-2"), records("campaign-1")
check(rc("campaign-2") == 0 and rc("campaign-1") == 0 and len(two) == 2 and two == one,
      f"campaign: two jobs on domains 62 and 63 give one job's records ({[(r['end'], r['sim_time_s']) for r in two]})")
outcomes = [[o["outcome"] for o in r["obstacles"]] for r in two]
check(all(r["contacts"] == 0 for r in two) and outcomes[0] != outcomes[1],
      f"campaign: the two variants differ (so crosstalk would show), no contact ({outcomes})")
check(all((out / "campaign-2" / f"stack-job-{j}.log").exists() for j in (0, 1)),
      "campaign: each job's stack wrote its own log")
WALL = {"wall_time_s", "real_time_factor", "time_split_s"}
def differ(a, b, path=""):
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in sorted(set(a) | set(b)) if k not in WALL and (path, k) != ("/stack", "name")
                for d in differ(a.get(k), b.get(k), f"{path}/{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differ(x, y, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {a!r} vs {b!r}"]
for s in ("cone_in_path_jet", "parking_lot", "traffic_van_meets_nose"):
    n, o = report(f"node-{s}"), report(f"ours-{s}")
    d = differ(n, o)
    whole_steps = "0 without their revolution, 0 without an estimate" in (out / f"ours-{s}.stack.log").read_text()
    check(rc(f"node-{s}") == 0 and rc(f"ours-{s}") == 0 and o["stack"]["steps"] > 300 and not d and whole_steps,
          f"our stack over ROS 2, {s}: the in-process report field for field ({o['end']}, {o['stack']['steps']} steps, "
          f"{len(o['contacts'])} contacts{'; differs: ' + '; '.join(d[:3]) if d else ''})")
c, steps = json.loads((out / "cyclone.json").read_text()), report("cyclone-run")["stack"]["steps"]
check(c["clocks"] == steps and c["clouds"] == steps and not c["bad"] and c["clock_steps_s"] == [0.1]
      and c["stamps_agree"] == c["clouds"],
      f"Cyclone DDS: read {c['clocks']} clocks and {c['clouds']} clouds ({c['points']} points) of {steps} steps, "
      f"each cloud's layout and points as sent, stamped with a clock it heard ({c['bad'][:2]})")
log = (out / "none.log").read_text()
check(rc("none") != 0 and "no subscriber of /velodyne_points" in log and "no publisher of /cmd_vel" in log,
      "none: refused, naming both missing topics")
sys.exit(1 if bad else 0)
PY
