#!/usr/bin/env python3
"""A run's ROS 2 bag read by three readers nobody here wrote: rosbags (its own MCAP and CDR
code; the bag directory with metadata.yaml, whose type hashes it recomputes from the embedded
schemas), Foxglove's mcap + mcap-ros2-support, and rosbags again on the bare .mcap. Every
message is decoded by each; the counts must agree with each other and with metadata.yaml; the
schema texts must be what rosbags' own ROS 2 Jazzy type store generates; and the messages must
agree with each other and with the run's JSON report.

usage: check_bag.py BAG_DIR RUN_NAME.mcap REPORT.json
"""
import json
import math
import sys
from collections import Counter
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader as Rosbag2Reader
from rosbags.typesys import Stores, get_typestore

EXPECTED = {
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/clock": "rosgraph_msgs/msg/Clock",
    "/velodyne_points": "sensor_msgs/msg/PointCloud2",
    "/localization/pose": "geometry_msgs/msg/PoseWithCovarianceStamped",
    "/ground_truth/odom": "nav_msgs/msg/Odometry",
    "/cmd_drive": "ackermann_msgs/msg/AckermannDriveStamped",
    "/planner/path": "nav_msgs/msg/Path",
    "/events": "std_msgs/msg/String",
    "/collision_model": "visualization_msgs/msg/MarkerArray",
    "/objects": "visualization_msgs/msg/MarkerArray",
    "/obstacles": "visualization_msgs/msg/MarkerArray",
}


def fail(msg):
    print(f"check_bag: FAIL: {msg}")
    sys.exit(1)


def ns(stamp):
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def with_rosbags(path):
    """Every message decoded by rosbags; per topic, the decoded messages in order."""
    out = {}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    return out


def main():
    bag_dir, mcap_name, report_path = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
    report = json.loads(report_path.read_text())
    mcap_file = bag_dir / mcap_name

    # 1. rosbag2 metadata, as ros2 bag info would read it.
    meta = Rosbag2Reader(bag_dir)
    meta.open()
    meta_counts = {c.topic: c.msgcount for c in meta.connections}
    types = {c.topic: c.msgtype for c in meta.connections}
    meta.close()
    grids = sorted(t for t in types if t.startswith("/map/level_"))
    levels = [t for t in grids if not t.endswith("/distance")]
    distances = [t for t in grids if t.endswith("/distance")]
    if {t: types[t] for t in types if t not in grids} != EXPECTED or not levels:
        fail(f"topics and types {types} are not {EXPECTED} and /map/level_<k>[/distance]")
    if distances != [t + "/distance" for t in levels]:
        fail(f"distance maps {distances} for the levels {levels}")
    if any(types[t] != "nav_msgs/msg/OccupancyGrid" for t in grids):
        fail(f"level maps of types {[types[t] for t in grids]}")

    # 2. Three readers decode every message.
    by_dir = with_rosbags(bag_dir)
    by_file = with_rosbags(mcap_file)
    foxglove = {}
    with open(mcap_file, "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        if reader.get_header().profile != "ros2":
            fail("the MCAP profile is not ros2")
        schemas = {}
        for schema, channel, message, ros_msg in reader.iter_decoded_messages():
            foxglove.setdefault(channel.topic, []).append((message.log_time, ros_msg))
            schemas[schema.name] = schema.data.decode()
    counts = [
        ("metadata.yaml", meta_counts),
        ("rosbags (directory)", {k: len(v) for k, v in by_dir.items()}),
        ("rosbags (.mcap)", {k: len(v) for k, v in by_file.items()}),
        ("mcap-ros2-support", {k: len(v) for k, v in foxglove.items()}),
    ]
    for name, c in counts[1:]:
        if c != counts[0][1]:
            fail(f"{name} counts {c} differ from metadata.yaml's {counts[0][1]}")

    # 3. The schema texts are rosbags' own for ROS 2 Jazzy.
    store = get_typestore(Stores.ROS2_JAZZY)
    for name, text in schemas.items():
        if name.startswith("ackermann_msgs"):
            continue  # not in the Jazzy base type store
        want, _ = store.generate_msgdef(name, ros_version=2)
        if text.strip() != want.strip():
            fail(f"schema of {name} differs from rosbags':\n{text}\n---\n{want}")

    # 4. The messages agree with each other and with the report.
    revolutions = len(by_dir["/velodyne_points"])
    sim_time = report["sim_time_s"]
    if abs(revolutions - sim_time * 10) > 5:  # the first few, taken before the stack starts, are not shown
        fail(f"{revolutions} clouds for {sim_time} s of simulated time (10 Hz)")
    if len(by_dir["/tf"]) != revolutions or len(by_dir["/planner/path"]) != revolutions:
        fail("/tf and /planner/path are not one per revolution")
    for (t, cloud), (_, fox) in zip(by_dir["/velodyne_points"], foxglove["/velodyne_points"]):
        names = [f.name for f in cloud.fields]
        if names != ["x", "y", "z", "intensity", "ring", "time"] or cloud.point_step != 22:
            fail(f"cloud fields {names}, point_step {cloud.point_step}")
        if cloud.width < 1000 or len(cloud.data) != cloud.width * 22 or fox.width != cloud.width:
            fail(f"cloud at {t}: width {cloud.width}, {len(cloud.data)} bytes")
        if ns(cloud.header.stamp) != t:
            fail(f"a cloud stamped {ns(cloud.header.stamp)} is logged at {t}")
    # Odometry at 20 Hz, revolutions at 10 Hz: the same instants to within a millisecond.
    truth = {round(t / 1e6): m for t, m in by_dir["/ground_truth/odom"]}
    matched = 0
    for t, tf in by_dir["/tf"]:
        gt = [x for x in tf.transforms if x.child_frame_id == "ground_truth/base_link"]
        if len(gt) != 1 or round(t / 1e6) not in truth:
            continue
        p, q = truth[round(t / 1e6)].pose.pose.position, gt[0].transform.translation
        if math.hypot(p.x - q.x, p.y - q.y) > 1e-6:
            fail(f"at {t} the true pose in /tf and /ground_truth/odom differ")
        matched += 1
    if matched < revolutions // 2:
        fail(f"only {matched} of {revolutions} revolutions have the true pose in both /tf and /ground_truth/odom")
    for topic in levels:
        grids = by_dir[topic]
        if abs(len(grids) - sim_time) > 2:
            fail(f"{len(grids)} {topic} grids for {sim_time} s (1 Hz)")
        for t, g in grids:
            cells = list(g.data)
            if len(cells) != g.info.width * g.info.height or g.info.resolution <= 0:
                fail(f"{topic} at {t}: {len(cells)} cells for {g.info.width} x {g.info.height}")
            if any(not (v == -1 or 0 <= v <= 100) for v in cells):
                fail(f"{topic} at {t}: values outside -1, 0..100")
        if not any(v >= 65 for _, g in grids for v in g.data):
            fail(f"{topic}: no occupied cell in any grid")
    for topic in distances:
        values = [v for _, g in by_dir[topic] for v in g.data]
        if abs(len(by_dir[topic]) - sim_time) > 2 or any(not 0 <= v <= 100 for v in values):
            fail(f"{topic}: {len(by_dir[topic])} grids, values outside 0..100 (percent of the cap)")
        if 0 not in values or 100 not in values:
            fail(f"{topic}: no obstacle (0) or no free space at the cap (100)")
    # Markers: the circles once (flat cylinders, frame-locked to base_link), the world's solids
    # once, the run-time obstacles every revolution after a DELETEALL (the crossing vehicle).
    (_, model), = by_dir["/collision_model"]
    if not model.markers or any(
        m.type != 3 or not m.frame_locked or m.header.frame_id != "base_link" or m.scale.x <= 0
        for m in model.markers
    ):
        fail("/collision_model is not flat cylinders locked to base_link")
    (_, objects), = by_dir["/objects"]
    if not objects.markers or any(m.header.frame_id != "map" for m in objects.markers):
        fail("/objects: no solids in map")
    obstacles = by_dir["/obstacles"]
    if len(obstacles) != revolutions or any(a.markers[0].action != 3 for _, a in obstacles):
        fail(f"/obstacles: {len(obstacles)} arrays for {revolutions} revolutions, each opening with DELETEALL")
    if not any(len(a.markers) > 1 for _, a in obstacles):
        fail("/obstacles: the crossing vehicle is never drawn")
    clock = [ns(m.clock) for _, m in by_dir["/clock"]]
    if clock != sorted(clock) or abs((clock[-1] - clock[0]) / 1e9 - sim_time) > 0.1:
        fail(f"/clock spans {(clock[-1] - clock[0]) / 1e9} s, the run {sim_time} s")
    stops = sum(json.loads(m.data)["kind"] == "Stop" for _, m in by_dir["/events"])
    if stops != len(report["stops"]):
        fail(f"{stops} Stop events against the report's {len(report['stops'])} stops")
    # The Foxglove layout shipped in docs/ shows topics this bag has.
    layout = json.loads((Path(__file__).parent.parent / "docs/foxglove-layout.json").read_text())
    shown = set()
    for panel in layout["configById"].values():
        shown.update(panel.get("topics", {}))
        shown.update(p["value"].split(".")[0] for p in panel.get("paths", []))
        if "topicPath" in panel:
            shown.add(panel["topicPath"])
    if shown - set(types):
        fail(f"docs/foxglove-layout.json shows topics the bag has not: {sorted(shown - set(types))}")
    total = sum(meta_counts.values())
    print(
        f"ok: {total} messages on {len(meta_counts)} topics decoded by rosbags (directory and .mcap) "
        f"and mcap-ros2-support; {revolutions} clouds, {len(levels)} level maps and their distance maps, "
        f"{matched} true poses matched, {len(model.markers)} circles, {len(objects.markers)} solids, "
        f"schemas as rosbags generates them, {stops} stops as the report, the Foxglove layout's {len(shown)} topics there"
    )


if __name__ == "__main__":
    main()
