#!/usr/bin/env python3
"""A minimal external taxi stack for `taxi-sim run --stack ros2`, as one rclpy node.

It reads the route (/route, transient local), the pose estimate (/localization/pose) and each
LiDAR revolution (/velodyne_points), and answers every revolution, once the estimate of the same
stamp is in, with a /cmd_vel
(geometry_msgs/TwistStamped) stamped with the revolution's stamp - the lockstep contract of
docs/external-stack.md. It steers by pure pursuit on the route and stops while any return lies in
a box ahead of the vehicle (the wheels' corridor, from a height above the ground up to the body's
top; returns within --min-range of the sensor are the vehicle itself): a template for your own stack, not a good one (no map, no memory of what it saw).

  deploy/ros2/follow_route.py [--speed 3.0] [--corridor-half-width 1.2] [--stop-within 8.0]
      [--min-range 2.5] [--min-height 0.15] [--max-height 1.8]

A hostile peer on purpose (CI checks the simulator's answer to each): --stop-answering-at S goes
silent, --nan-at S commands NaN, --wrong-stamp-from S stamps each command with the revolution
before, --late-at S --late-by W answers one revolution W wall seconds late, --crash-at S exits with
status 3 mid-run, --flood N sends N commands for other times before each answer, --no-subscribe
never subscribes to the cloud.
"""
import argparse
import math
import os
import sys
import time

import numpy as np
import rclpy
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TwistStamped
from nav_msgs.msg import Path
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import PointCloud2

EPOCH_S = 1_704_067_200  # taxi-sim stamps sim time t as 2024-01-01T00:00:00Z + t


def qos(depth, latched=False):
    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE,
        history=HistoryPolicy.KEEP_LAST,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )


def stamp_key(stamp):
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def xyz(cloud):
    """The x, y, z columns of a PointCloud2 (float32 fields), as an (n, 3) array."""
    offsets = {f.name: f.offset for f in cloud.fields}
    raw = np.frombuffer(bytes(cloud.data), dtype=np.uint8).reshape(-1, cloud.point_step)
    return np.stack(
        [raw[:, offsets[k]:offsets[k] + 4].copy().view("<f4")[:, 0] for k in "xyz"], axis=1
    )


class FollowRoute(Node):
    def __init__(self, args):
        super().__init__("follow_route", parameter_overrides=[Parameter("use_sim_time", value=True)])
        self.args = args
        self.route = None
        self.pose = None
        self.answered = 0
        self.was_late = False
        self.pub = self.create_publisher(TwistStamped, "/cmd_vel", qos(10))
        self.create_subscription(Path, "/route", self.on_route, qos(1, latched=True))
        self.create_subscription(
            PoseWithCovarianceStamped, "/localization/pose", self.on_pose, qos(10)
        )
        if not args.no_subscribe:
            self.create_subscription(PointCloud2, "/velodyne_points", self.on_cloud, qos(1))
        self.clouds, self.poses = {}, {}
        self.previous_stamp = None
        self.ground_truth = 0
        if args.count_ground_truth:  # a tool's view: the stack itself never steers by it
            self.create_subscription(PoseStamped, "/ground_truth/pose", self.on_truth, qos(10))

    def on_truth(self, _m):
        self.ground_truth += 1

    def on_route(self, m):
        self.route = np.array([[p.pose.position.x, p.pose.position.y] for p in m.poses])
        self.answer_ready()

    def on_pose(self, m):
        p, q = m.pose.pose.position, m.pose.pose.orientation
        self.poses[stamp_key(m.header.stamp)] = (p.x, p.y, 2.0 * math.atan2(q.z, q.w))
        self.answer_ready()

    def on_cloud(self, cloud):
        self.clouds[stamp_key(cloud.header.stamp)] = cloud
        self.answer_ready()

    def answer_ready(self):
        """Answers each revolution once the pose of the same stamp is in too (the topics arrive
        in any order), and not before the route (latched, it may come after the first
        revolution): the same inputs give the same command, so a run repeats."""
        if self.route is None:
            return
        for key in sorted(set(self.clouds) & set(self.poses)):
            self.pose = self.poses.pop(key)
            self.answer(self.clouds.pop(key))
        # A revolution the faults lost comes with no cloud: forget poses left behind.
        for key in [k for k in self.poses if self.clouds and k < min(self.clouds)]:
            del self.poses[key]

    def steer(self):
        """Yaw rate towards the route point `lookahead` metres ahead (pure pursuit)."""
        if self.route is None or self.pose is None or len(self.route) < 2:
            return 0.0
        x, y, yaw = self.pose
        d = np.hypot(self.route[:, 0] - x, self.route[:, 1] - y)
        i = int(np.argmin(d))
        ahead = [k for k in range(i, len(self.route)) if d[k] >= self.args.lookahead]
        gx, gy = self.route[ahead[0]] if ahead else self.route[-1]
        alpha = math.atan2(gy - y, gx - x) - yaw
        alpha = math.atan2(math.sin(alpha), math.cos(alpha))
        dist = max(math.hypot(gx - x, gy - y), 1e-3)
        return 2.0 * self.args.speed * math.sin(alpha) / dist

    def blocked(self, cloud):
        a = self.args
        p = xyz(cloud)
        if len(p) == 0:
            return False
        # The sensor frame's ground is its lowest returns; heights are measured from it.
        ground = np.percentile(p[:, 2], 5)
        h = p[:, 2] - ground
        box = (p[:, 0] > 0.0) & (p[:, 0] < a.stop_within) & (np.abs(p[:, 1]) < a.corridor_half_width)
        near = np.hypot(p[:, 0], p[:, 1]) < a.min_range
        return bool(np.any(box & ~near & (h > a.min_height) & (h < a.max_height)))

    def answer(self, cloud):
        t = cloud.header.stamp.sec - EPOCH_S + cloud.header.stamp.nanosec * 1e-9
        a = self.args
        at = lambda s: s is not None and t >= s - 1e-6  # noqa: E731
        if at(a.stop_answering_at):
            return
        if at(a.crash_at):
            self.get_logger().error(f"crashing on purpose at t = {t:.3f} s")
            sys.stdout.flush()
            os._exit(3)
        m = TwistStamped()
        m.header.stamp = cloud.header.stamp
        m.header.frame_id = "base_link"
        if not self.blocked(cloud):
            m.twist.linear.x = a.speed
            m.twist.angular.z = self.steer()
        if at(a.nan_at):
            m.twist.linear.x = float("nan")
        if at(a.wrong_stamp_from) and self.previous_stamp is not None:
            m.header.stamp = self.previous_stamp
        self.previous_stamp = cloud.header.stamp
        if at(a.late_at) and not self.was_late:
            self.was_late = True
            time.sleep(a.late_by)
        for k in range(a.flood):
            junk = TwistStamped()
            junk.header.stamp.sec = cloud.header.stamp.sec + (k % 7) - 3
            junk.header.stamp.nanosec = (cloud.header.stamp.nanosec + 1000 * (k + 1)) % 1_000_000_000
            junk.twist.linear.x = 100.0  # absurd: taken, it would end the run stack_failed
            self.pub.publish(junk)
        self.pub.publish(m)
        self.answered += 1
        if self.answered == 20:  # the simulator's topics, as the graph shows them 2 s in
            topics = sorted(name for name, _ in self.get_topic_names_and_types())
            self.get_logger().info(f"topics seen: {' '.join(topics)}")



def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", type=float, default=3.0, help="m/s")
    ap.add_argument("--lookahead", type=float, default=15.0, help="pure pursuit, m (>= 2 wheelbases)")
    ap.add_argument("--corridor-half-width", type=float, default=1.2, help="m, sensor frame")
    ap.add_argument("--stop-within", type=float, default=8.0, help="m ahead of the sensor")
    ap.add_argument(
        "--min-range", type=float, default=2.5, help="m: nearer returns are the vehicle itself"
    )
    ap.add_argument("--min-height", type=float, default=0.15, help="m above the ground")
    ap.add_argument("--max-height", type=float, default=1.8, help="m above the ground")
    ap.add_argument("--stop-answering-at", type=float, help="sim s: go silent (a test)")
    ap.add_argument("--nan-at", type=float, help="sim s: command NaN (a test)")
    ap.add_argument("--wrong-stamp-from", type=float, help="sim s: answer with the last stamp (a test)")
    ap.add_argument("--late-at", type=float, help="sim s: answer this revolution late (a test)")
    ap.add_argument("--late-by", type=float, default=2.0, help="wall s, with --late-at")
    ap.add_argument("--crash-at", type=float, help="sim s: exit with status 3 (a test)")
    ap.add_argument("--flood", type=int, default=0, help="junk commands before each answer (a test)")
    ap.add_argument("--no-subscribe", action="store_true", help="never take the cloud (a test)")
    ap.add_argument(
        "--count-ground-truth", action="store_true", help="count /ground_truth/pose messages (a test)"
    )
    ap.add_argument("--exit-after-s", type=float, default=600.0, help="wall s")
    args = ap.parse_args()
    rclpy.init()
    node = FollowRoute(args)
    end = time.monotonic() + args.exit_after_s
    try:
        while rclpy.ok() and time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.2)
    except KeyboardInterrupt:
        pass
    node.get_logger().info(f"answered {node.answered} revolutions")
    if args.count_ground_truth:
        node.get_logger().info(f"ground truth messages: {node.ground_truth}")
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
