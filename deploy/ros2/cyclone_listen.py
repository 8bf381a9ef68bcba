#!/usr/bin/env python3
"""A second DDS implementation reads the simulator: Eclipse Cyclone DDS (PyPI `cyclonedds`,
no ROS at all) subscribes to `/clock` and `/velodyne_points` as plain DDS topics (`rt/clock`,
`rt/velodyne_points`, the ROS 2 type names), checks each cloud's layout and points, and prints a
JSON summary when the simulator has gone quiet for `--quiet-s` seconds (or at `--max-s`).

    ROS_DOMAIN_ID=64 python3 deploy/ros2/cyclone_listen.py --out summary.json
"""
import argparse
import json
import math
import os
import struct
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32, sequence, uint8, uint32
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class PointField(IdlStruct, typename="sensor_msgs::msg::dds_::PointField_"):
    name: str
    offset: uint32
    datatype: uint8
    count: uint32


@dataclass
class PointCloud2(IdlStruct, typename="sensor_msgs::msg::dds_::PointCloud2_"):
    header: Header
    height: uint32
    width: uint32
    fields: sequence[PointField]
    is_bigendian: bool
    point_step: uint32
    row_step: uint32
    data: sequence[uint8]
    is_dense: bool


LAYOUT = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7), ("ring", 16, 4), ("time", 18, 7)]


def check_cloud(m):
    """Why the cloud is not the simulator's Velodyne layout, or None."""
    got = [(f.name, f.offset, f.datatype) for f in m.fields]
    if got != LAYOUT:
        return f"fields {got}"
    if m.point_step != 22 or m.is_bigendian or len(m.data) != 22 * m.width * m.height:
        return f"point_step {m.point_step}, {len(m.data)} bytes for {m.width} x {m.height}"
    data = bytes(m.data)
    for i in range(0, len(data), 22 * 997):  # every 997th point
        x, y, z, _intensity, ring, _t = struct.unpack_from("<ffffHf", data, i)
        if not all(math.isfinite(v) for v in (x, y, z)) or ring >= 32 or math.hypot(x, y) > 200:
            return f"point {i // 22}: {(x, y, z, ring)}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--quiet-s", type=float, default=5.0)
    ap.add_argument("--max-s", type=float, default=300.0)
    args = ap.parse_args()
    dp = DomainParticipant(int(os.environ.get("ROS_DOMAIN_ID", "0")))
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(50))
    clock = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=qos)
    cloud = DataReader(dp, Topic(dp, "rt/velodyne_points", PointCloud2), qos=qos)
    summary = {"clocks": 0, "clouds": 0, "points": 0, "bad": [], "clock_steps_s": set(),
               "stamps_agree": 0}
    started = time.monotonic()
    last_heard = None
    last_clock = None
    clock_ns = set()
    cloud_ns = []  # checked against the clocks at the end: DDS keeps no order between topics
    print("[cyclone] listening", flush=True)
    while time.monotonic() - started < args.max_s:
        got = False
        for m in clock.take(N=100):
            got = True
            if not isinstance(m, Clock):  # an instance's state changed (its writer left)
                continue
            summary["clocks"] += 1
            t = m.clock.sec * 1_000_000_000 + m.clock.nanosec
            clock_ns.add(t)
            if last_clock is not None:
                summary["clock_steps_s"].add(round((t - last_clock) / 1e9, 6))
            last_clock = t
        for m in cloud.take(N=10):
            got = True
            if not isinstance(m, PointCloud2):
                continue
            summary["clouds"] += 1
            summary["points"] += m.width * m.height
            why = check_cloud(m)
            if why:
                summary["bad"].append(why)
            cloud_ns.append(m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec)
        if got:
            last_heard = time.monotonic()
        elif last_heard is not None and time.monotonic() - last_heard > args.quiet_s:
            break
        time.sleep(0.005)
    summary["stamps_agree"] = sum(t in clock_ns for t in cloud_ns)
    summary["clock_steps_s"] = sorted(summary["clock_steps_s"])[:5]
    with open(args.out, "w") as f:
        json.dump(summary, f)
    print(f"[cyclone] {summary['clocks']} clocks, {summary['clouds']} clouds "
          f"({summary['points']} points), {len(summary['bad'])} bad", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
