#!/usr/bin/env python3
"""CI check of `taxi-sim bench representations --out DIR`: every representation measured on
the scene, OctoMap through its own binding included, and the properties the comparison rests on.

Usage: check_representations.py DIR/representations.json
"""
import json
import sys

WANTED = [
    "multi-height, cumulative",
    "multi-height, banded",
    "3D voxels (dense)",
    "2.5D elevation interval",
    "OctoMap 0.2 m",
]


def main(path):
    scenes = json.load(open(path))
    assert scenes, f"{path}: no scene"
    for s in scenes:
        rows = {r["name"]: r for r in s["rows"]}
        missing = [w for w in WANTED if w not in rows]
        assert not missing, f"{s['scenario']}: rows missing: {missing} (notes: {s['notes']})"
        poses, colliding = s["poses"]
        assert poses >= 500 and colliding > 0, s["poses"]
        for name, r in rows.items():
            j = r["judged"]["all"]
            assert j["poses"] == poses, (name, j)
            assert r["memory_window_bytes"] > 0 and (r["insert_ms"] is None or r["insert_ms"] > 0), (name, r)
        # The thesis' grids never say clear where the dense 3D grid says colliding.
        assert rows["multi-height, cumulative"]["vs_voxels"][1] == 0, rows["multi-height, cumulative"]["vs_voxels"]
        # OctoMap's own pose checks agree with ours on its voxels.
        for res, agree, n in s["octomap_agreement"]:
            assert n > 0 and agree >= 0.95 * n, (res, agree, n)
        dense = rows["3D voxels (dense)"]["memory_window_bytes"]
        grids = rows["multi-height, cumulative"]["memory_window_bytes"]
        print(
            f"ok: {s['scenario']}: {poses} poses ({colliding} colliding), {len(rows)} representations; "
            f"3D voxels take {dense / grids:.1f}x the grids' memory; OctoMap agrees with itself on "
            + ", ".join(f"{a}/{n} at {r} m" for r, a, n in s["octomap_agreement"])
        )


if __name__ == "__main__":
    main(sys.argv[1])
