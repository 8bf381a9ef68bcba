#!/usr/bin/env python3
"""Checks a taxi-sim Rerun recording: every entity path docs/commands.md lists is there, with the
archetype it should hold, on the `sim_time` timeline. Exits 1 naming what is missing.

Usage: check_rrd.py RUN.rrd [--airport]   (with the rerun-sdk matching the crate, see .ci/run)
--airport: also the airport's pavement outlines (`/world/areas`) and parked aircraft.
"""

import sys

import rerun as rr

# (entity path or prefix ending in "/", archetype) - docs/commands.md "Replay in Rerun" lists them.
EXPECTED = [
    ("/world/ground", "rerun.archetypes.Boxes3D"),
    ("/world/objects/", None),
    ("/world/route", "rerun.archetypes.LineStrips3D"),
    ("/world/obstacles/", None),
    ("/world/vehicle", "rerun.archetypes.Transform3D"),
    ("/world/vehicle/parts/", None),
    ("/world/vehicle/circles/level_0", "rerun.archetypes.LineStrips3D"),
    ("/world/vehicle/circles/level_1", "rerun.archetypes.LineStrips3D"),
    ("/world/lidar", "rerun.archetypes.Points3D"),
    ("/world/lidar", "rerun.archetypes.AnnotationContext"),
    ("/world/maps/level_0/occupancy", "rerun.archetypes.GridMap"),
    ("/world/maps/level_1/occupancy", "rerun.archetypes.GridMap"),
    ("/maps/level_0/distance", "rerun.archetypes.DepthImage"),
    ("/maps/level_1/distance", "rerun.archetypes.DepthImage"),
    ("/world/planner/candidates", "rerun.archetypes.LineStrips3D"),
    ("/world/planner/chosen", "rerun.archetypes.LineStrips3D"),
    ("/world/localization/particles", "rerun.archetypes.Points3D"),
    ("/world/localization/covariance_2sigma", "rerun.archetypes.LineStrips3D"),
    ("/plots/localization/cross_track_error_m", "rerun.archetypes.Scalars"),
    ("/plots/localization/cross_track_sigma_m", "rerun.archetypes.Scalars"),
    ("/plots/speed_m_s", "rerun.archetypes.Scalars"),
    ("/plots/steering_rad", "rerun.archetypes.Scalars"),
    ("/plots/clearance_m/level_0", "rerun.archetypes.Scalars"),
    ("/plots/clearance_m/level_1", "rerun.archetypes.Scalars"),
    ("/plots/real_time_factor", "rerun.archetypes.Scalars"),
    ("/plots/speed_scale", "rerun.archetypes.Scalars"),
    ("/events", "rerun.archetypes.TextLog"),
]


AIRPORT = [
    ("/world/areas", "rerun.archetypes.LineStrips3D"),
    ("/world/objects/stand_S2_", None),  # a prefix: the parked A320's parts
]


def main() -> int:
    args = sys.argv[1:]
    airport = "--airport" in args
    args = [a for a in args if a != "--airport"]
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    path = args[0]
    schema = rr.experimental.RrdReader(path).store().schema()
    columns = schema.component_columns()
    held = {(c.entity_path, c.archetype) for c in columns}
    paths = {c.entity_path for c in columns}
    missing = []
    for entity, archetype in EXPECTED + (AIRPORT if airport else []):
        if entity.endswith(("/", "_")):
            ok = any(p.startswith(entity) for p in paths)
        elif archetype is None:
            ok = entity in paths
        else:
            ok = (entity, archetype) in held
        if not ok:
            missing.append(f"{entity} ({archetype or 'any'})")
    timelines = {c.name for c in schema.index_columns()}
    if "sim_time" not in timelines:
        missing.append(f"the sim_time timeline (timelines: {sorted(timelines)})")
    if missing:
        print(f"{path}: missing " + ", ".join(missing), file=sys.stderr)
        print(f"{path}: has {sorted(paths)}", file=sys.stderr)
        return 1
    print(f"{path}: {len(paths)} entity paths, every expected one present")
    return 0


if __name__ == "__main__":
    sys.exit(main())
