#!/usr/bin/env python3
"""OctoMap benchmark: builds the real OctoMap library's OcTree from a run's lidar revolutions
(through its published Python binding, octomap-python) and measures insertion time, memory,
the occupied voxels inside a window, and vehicle pose checks, for comparison with our maps.

usage: octomap_bench.py DIR [--resolution 0.2] [--out DIR/octomap_0.2.json]
                            [--voxels DIR/octomap_0.2_voxels.npy] [--query bbx|search|labels]

Input DIR (written by the Rust side):
  points.npy     float32 (M, 3): every return of every revolution, world frame (x forward/east,
                 y left, z up, metres; the ground is z = 0), revolutions concatenated
  offsets.npy    int64 (K+1,): revolution k is points[offsets[k]:offsets[k+1]]
  origins.npy    float64 (K, 3): the sensor origin of each revolution, world frame
  meta.json      {"max_range_m", "z_shift_m", "window": {"x0", "y0", "x1", "y1", "z_top"}}
  cylinders.npy  float64 (P, C, 5): per sample pose, the vehicle's parts as vertical cylinders
                 [x, y, radius, z_lo, z_hi], world frame; rows with radius <= 0 are padding

What it does:
  1. OcTree(resolution); each revolution goes in with ONE insertPointCloud(points, origin,
     maxrange=max_range_m) call - the library's own insertion (every ray carved free, the
     endpoint voxel occupied, occupied winning over free within a scan), with the binding's
     defaults lazy_eval=False (inner nodes updated and the tree pruned as it goes, so
     updateInnerOccupancy() is not needed; it is timed anyway for information) and
     discretize=False. Each call is timed with time.perf_counter() (wall, "insert_ms"), and
     with time.process_time() ("insert_cpu_ms": CPU time, less disturbed by a loaded machine).
     The z shift: z_shift_m (-0.05) is added to every z (points and origins) before insertion.
     OctoMap's voxel boundaries lie at k*resolution in its own frame, so in the world they then
     lie at z = 0.05 m + k*resolution: the ground returns (z ~ 0 +- 4 mm) fall inside the layer
     just below 0.05 m, not on a boundary. This is the standard choice of placing the ground
     mid-voxel so that the ground layer can be told apart; that layer is then ignored by every
     query here (voxel centres must have world z >= 0.05 m, FLOOR_Z_M) - the same floor the
     other representations use.
  2. Measures memoryUsage(), memoryFullGrid(), size(), getNumLeafNodes(), resolution.
     The binding has no prune() (only pruneNode() of one node); with lazy_eval=False the
     library prunes during insertion, so nothing is lost.
  3. Exports the occupied voxels inside the window: the leaves from begin_leafs_bbx() over the
     window (the leaf iterator restricted by the library to the window's key box), occupancy by
     tree.isNodeOccupied(leaf); a pruned leaf larger than the resolution is expanded into its
     resolution-sized voxel centres. Kept: centres with x0 <= x < x1, y0 <= y < y1 and
     FLOOR_Z_M <= z < z_top (world z, the shift undone); written as float32 (N, 3), world frame,
     sorted by x, then y, then z.
  4. Pose checks through the library's query structure: a pose collides iff one of its part
     cylinders contains the centre of an occupied voxel: horizontal distance from the axis
     < radius and world z within [z_lo, z_hi] (and >= FLOOR_Z_M). Methods (--query):
       bbx    (default, the fastest: on a 10-revolution synthetic airport scene, median
              2.2 ms per 4-part pose at 0.2 m and 16 ms at 0.1 m, against 11 / 92 ms for
              search and 15 / 98 ms for labels) per cylinder, begin_leafs_bbx() over the
              cylinder's bounding box; occupied leaves expanded to voxel centres and tested;
              stops at the first hit
       search per cylinder, tree.search() at every resolution-sized voxel centre inside it;
              stops at the first occupied one
       labels per cylinder, the binding's getLabels() on those same centres (no early stop)
     Each pose's check (all its cylinders) is timed.
  5. Writes --voxels, then the JSON --out (each atomically: PATH.tmp then os.replace):
     library, version, octomap_version, resolution_m, revolutions, points,
     insert_ms {median, mean, total, per_revolution}, insert_cpu_ms {median, mean, total},
     insert_options, binding_copy_ms_estimate, openmp, memory_bytes, memory_full_grid_bytes,
     nodes (size()), leaves, tree_depth, update_inner_occupancy_ms, prune_ms (null),
     prune_note, z_shift_m, floor_z_m, window, occupied_voxels_exported, export_ms,
     pose_check_us {median, mean, per_pose}, pose_answers, query_method.
     Medians are null when there is nothing to time (no poses).

Binding facts (octomap-python 1.10.0.0, OctoMap 1.10.0 compiled in): insertPointCloud needs a
float64 (N, 3) array and a float64 (3,) origin (a float32 array is refused with "Buffer dtype
mismatch"), and copies the points into an octomap::Pointcloud with a Python-level loop over
the rows; that copy is inside the timed call, and its cost is estimated separately
("binding_copy_ms_estimate": the same call on a scratch tree with a 1 um maxrange, so that
almost no ray is traced; ~15-25 ms per 60,000 points, about 1% of the call). The wheel is
built without OpenMP: insertion is single-threaded. Cost seen on a synthetic 60,000-return
revolution (mean range 28 m, max range 100 m): ~3.3 s CPU at 0.2 m, ~12 s at 0.1 m, and the
tree grows to ~2 GB after 10 such revolutions at 0.1 m (free space barely prunes).

Exit status: 0 done; 2 bad input (one line on stderr naming the file and what is wrong);
3 the octomap binding (or numpy) cannot be imported; 1 an output cannot be written.
"""
import argparse
import json
import math
import os
import sys
import time

FLOOR_Z_M = 0.05  # world z of the top of the ground layer; voxel centres below it are ignored
PROG = "octomap_bench"


class BadInput(Exception):
    """Bad input: the file (or option) it concerns and what is wrong with it."""

    def __init__(self, where, what):
        super().__init__(f"{where}: {what}")


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message):
        print(f"{PROG}: {message}", file=sys.stderr)
        sys.exit(2)


def parse_args(argv):
    p = Parser(prog="octomap_bench.py", description=__doc__.splitlines()[0])
    p.add_argument("dir", metavar="DIR", help="input directory written by the Rust side")
    p.add_argument("--resolution", type=float, default=0.2, help="voxel edge, m (default 0.2)")
    p.add_argument("--out", help="JSON report (default DIR/octomap_RES.json)")
    p.add_argument("--voxels",
                   help="occupied voxel centres, .npy (default DIR/octomap_RES_voxels.npy)")
    p.add_argument("--query", choices=("bbx", "search", "labels"), default="bbx",
                   help="pose-check method (default bbx, the fastest)")
    a = p.parse_args(argv)
    if not (math.isfinite(a.resolution) and a.resolution > 0):
        print(f"{PROG}: --resolution: must be a finite number > 0, got {a.resolution}",
              file=sys.stderr)
        sys.exit(2)
    res_tag = f"{a.resolution:g}"
    if a.out is None:
        a.out = os.path.join(a.dir, f"octomap_{res_tag}.json")
    if a.voxels is None:
        a.voxels = os.path.join(a.dir, f"octomap_{res_tag}_voxels.npy")
    if not os.path.isdir(a.dir):
        return a  # reported by load_input
    for opt, path in (("--out", a.out), ("--voxels", a.voxels)):
        # checked now rather than after a long run
        parent = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(parent) or not os.access(parent, os.W_OK):
            print(f"{PROG}: {opt} {path}: directory {parent} does not exist or is not writable",
                  file=sys.stderr)
            sys.exit(2)
    return a


def import_libs():
    """numpy and octomap, or exit 3."""
    try:
        import numpy
    except Exception as e:  # noqa: BLE001 - any failure means "not installed"
        print(f"{PROG}: cannot import numpy ({type(e).__name__}: {e})", file=sys.stderr)
        sys.exit(3)
    try:
        import octomap
    except Exception as e:  # noqa: BLE001
        print(f"{PROG}: the OctoMap Python binding is not installed: cannot import octomap "
              f"({type(e).__name__}: {e}); install it with `pip install octomap-python`",
              file=sys.stderr)
        sys.exit(3)
    return numpy, octomap


# ---------------------------------------------------------------------------------------------
# Input


def load_npy(np, d, name, kind, itemsize, shape):
    """The array in d/name, checked: dtype kind/itemsize, `shape` like "(M, 3)" (its last
    entry, when a number, is the required length of the last axis), all finite."""
    path = os.path.join(d, name)
    if not os.path.isfile(path):
        raise BadInput(path, "missing")
    try:
        a = np.load(path, allow_pickle=False)
    except Exception as e:  # noqa: BLE001 - a corrupt file is bad input
        raise BadInput(path, f"not a readable .npy file ({type(e).__name__}: {e})") from None
    if not isinstance(a, np.ndarray):
        raise BadInput(path, "not a single .npy array")
    want = f"{'float' if kind == 'f' else 'int'}{8 * itemsize}"
    if a.dtype.kind != kind or a.dtype.itemsize != itemsize:
        raise BadInput(path, f"dtype {a.dtype}, expected {want}")
    dims = [x.strip() for x in shape.strip("()").split(",") if x.strip()]
    if a.ndim != len(dims) or (dims[-1].isdigit() and a.shape[-1] != int(dims[-1])):
        raise BadInput(path, f"shape {a.shape}, expected {shape}")
    if kind == "f" and not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        raise BadInput(path, f"non-finite number at index {tuple(int(i) for i in bad)}")
    return a.astype(a.dtype.newbyteorder("="), copy=False)


def number(where, obj, key):
    v = obj.get(key) if isinstance(obj, dict) else None
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise BadInput(where, f"{key}: missing or not a number")
    if not math.isfinite(v):
        raise BadInput(where, f"{key}: not finite ({v})")
    return float(v)


def load_meta(d):
    path = os.path.join(d, "meta.json")
    if not os.path.isfile(path):
        raise BadInput(path, "missing")
    try:
        with open(path, encoding="utf-8") as f:
            meta = json.load(f)
    except (OSError, ValueError) as e:
        raise BadInput(path, f"not readable JSON ({e})") from None
    if not isinstance(meta, dict):
        raise BadInput(path, "not a JSON object")
    max_range = number(path, meta, "max_range_m")
    if max_range <= 0:
        raise BadInput(path, f"max_range_m must be > 0, got {max_range}")
    z_shift = number(path, meta, "z_shift_m")
    w = meta.get("window")
    if not isinstance(w, dict):
        raise BadInput(path, "window: missing or not an object")
    win = {k: number(path + " window", w, k) for k in ("x0", "y0", "x1", "y1", "z_top")}
    if not (win["x1"] > win["x0"] and win["y1"] > win["y0"]):
        raise BadInput(path, f"window: needs x0 < x1 and y0 < y1, got {win}")
    if win["z_top"] <= 0:
        raise BadInput(path, f"window: z_top must be > 0, got {win['z_top']}")
    return max_range, z_shift, win


def load_input(np, d, resolution):
    if not os.path.isdir(d):
        raise BadInput(d, "not a directory")
    points = load_npy(np, d, "points.npy", "f", 4, "(M, 3)")
    offsets = load_npy(np, d, "offsets.npy", "i", 8, "(K+1,)")
    origins = load_npy(np, d, "origins.npy", "f", 8, "(K, 3)")
    max_range, z_shift, win = load_meta(d)
    cylinders = load_npy(np, d, "cylinders.npy", "f", 8, "(P, C, 5)")

    po = os.path.join(d, "offsets.npy")
    m = points.shape[0]
    if offsets.shape[0] < 2:
        raise BadInput(po, f"{offsets.shape[0]} entries; needs K+1 >= 2 (at least one revolution)")
    if offsets[0] != 0:
        raise BadInput(po, f"starts at {offsets[0]}, expected 0")
    steps = np.diff(offsets)
    if (steps < 0).any():
        i = int(np.argmax(steps < 0))
        raise BadInput(po, f"not monotonic: offsets[{i + 1}] = {offsets[i + 1]} "
                           f"< offsets[{i}] = {offsets[i]}")
    if offsets[-1] != m:
        raise BadInput(po, f"ends at {offsets[-1]}, expected M = {m} (the rows of points.npy)")
    k = offsets.shape[0] - 1
    if origins.shape[0] != k:
        raise BadInput(os.path.join(d, "origins.npy"),
                       f"{origins.shape[0]} origins for {k} revolutions (offsets.npy)")
    pc = os.path.join(d, "cylinders.npy")
    real = cylinders[..., 2] > 0
    if (cylinders[..., 3][real] > cylinders[..., 4][real]).any():
        p, c = np.argwhere(real & (cylinders[..., 3] > cylinders[..., 4]))[0]
        raise BadInput(pc, f"pose {p} part {c}: z_lo > z_hi")

    # OctoMap's keys are 16 bits: coordinates must lie within +-32768 voxels of the origin.
    limit = 32768 * resolution
    for name, arr in (("points.npy", points), ("origins.npy", origins)):
        if arr.size:
            reach = max(float(np.abs(arr[:, :2]).max()), float(np.abs(arr[:, 2] + z_shift).max()))
            if reach >= limit:
                raise BadInput(os.path.join(d, name),
                               f"coordinates reach {reach:.1f} m, beyond OctoMap's +-{limit:.1f} m "
                               f"at resolution {resolution}")
    return points, offsets, origins, max_range, z_shift, win, cylinders


# ---------------------------------------------------------------------------------------------
# Voxel centres


def expand_leaves(np, leaves, res):
    """(L, 4) leaves [x, y, z, size] in OctoMap's frame -> (N, 3) float64 centres of their
    resolution-sized voxels, snapped to the exact grid (k + 0.5) * res."""
    if len(leaves) == 0:
        return np.zeros((0, 3))
    leaves = np.asarray(leaves, dtype=np.float64)
    n = np.maximum(1, np.rint(leaves[:, 3] / res).astype(np.int64))
    # index of each leaf's lowest voxel
    k0 = np.rint((leaves[:, :3] - 0.5 * n[:, None] * res) / res).astype(np.int64)
    out = [k0[n == 1]]
    for size in np.unique(n[n > 1]):
        g = np.stack(np.meshgrid(*[np.arange(size)] * 3, indexing="ij"), -1).reshape(-1, 3)
        out.append((k0[n == size][:, None, :] + g[None]).reshape(-1, 3))
    return (np.concatenate(out).astype(np.float64) + 0.5) * res


def in_cylinder(np, centres_world, cyl):
    """Mask of world-frame voxel centres inside part cylinder [x, y, r, z_lo, z_hi] (above
    the floor)."""
    x, y, r, z_lo, z_hi = cyl
    c = centres_world
    return (((c[:, 0] - x) ** 2 + (c[:, 1] - y) ** 2 < r * r)
            & (c[:, 2] >= max(z_lo, FLOOR_Z_M)) & (c[:, 2] <= z_hi))


def cylinder_grid(np, cyl, res, z_shift):
    """World-frame centres of all resolution-sized voxels whose centre lies in the cylinder."""
    x, y, r, z_lo, z_hi = cyl
    z_lo = max(z_lo, FLOOR_Z_M)
    if z_lo > z_hi:
        return np.zeros((0, 3))
    # OctoMap frame centres are (k + 0.5) * res; world z = that - z_shift
    kx = np.arange(math.floor((x - r) / res) - 1, math.ceil((x + r) / res) + 1)
    ky = np.arange(math.floor((y - r) / res) - 1, math.ceil((y + r) / res) + 1)
    kz = np.arange(math.floor((z_lo + z_shift) / res) - 1, math.ceil((z_hi + z_shift) / res) + 1)
    g = np.stack(np.meshgrid(kx, ky, kz, indexing="ij"), -1).reshape(-1, 3)
    c = (g + 0.5) * res
    c[:, 2] -= z_shift
    return c[in_cylinder(np, c, cyl)]


# ---------------------------------------------------------------------------------------------
# Pose checks


def make_pose_check(np, octomap, tree, res, z_shift, method):
    """A function (cylinders (C, 5)) -> bool: does the pose collide, by `method`."""
    occupied = tree.isNodeOccupied
    null = octomap.NullPointerException

    def cyl_bbx(cyl):
        x, y, r, z_lo, z_hi = cyl
        lo = np.array([x - r, y - r, max(z_lo, FLOOR_Z_M) + z_shift])
        hi = np.array([x + r, y + r, z_hi + z_shift])
        if lo[2] > hi[2]:
            return False
        for it in tree.begin_leafs_bbx(lo, hi):
            if occupied(it):
                c = expand_leaves(np, [(it.getX(), it.getY(), it.getZ(), it.getSize())], res)
                c[:, 2] -= z_shift
                if in_cylinder(np, c, cyl).any():
                    return True
        return False

    def cyl_search(cyl):
        c = cylinder_grid(np, cyl, res, z_shift)
        c[:, 2] += z_shift
        search = tree.search
        for p in c.tolist():
            try:
                if occupied(search(p)):
                    return True
            except null:  # unknown space: no node
                pass
        return False

    def cyl_labels(cyl):
        c = cylinder_grid(np, cyl, res, z_shift)
        if len(c) == 0:
            return False
        c[:, 2] += z_shift
        return bool((tree.getLabels(np.ascontiguousarray(c)) == 1).any())

    one = {"bbx": cyl_bbx, "search": cyl_search, "labels": cyl_labels}[method]

    def check(cyls):
        return any(one(tuple(map(float, row))) for row in cyls if row[2] > 0)

    return check


QUERY_METHODS = {
    "bbx": "per part cylinder, OcTree.begin_leafs_bbx() over its bounding box (OctoMap frame); "
           "occupied leaves (isNodeOccupied) expanded to resolution-sized voxel centres and "
           "tested against the cylinder; stops at the first hit",
    "search": "per part cylinder, OcTree.search() at every resolution-sized voxel centre inside "
              "it; isNodeOccupied on the node found (unknown space has none); stops at the "
              "first occupied one",
    "labels": "per part cylinder, OcTree.getLabels() on every resolution-sized voxel centre "
              "inside it (the binding's search loop); no early stop",
}


# ---------------------------------------------------------------------------------------------
# Output


def write_atomic(path, write):
    tmp = path + ".tmp"
    try:
        with open(tmp, "wb") as f:
            write(f)
        os.replace(tmp, path)
    except OSError as e:
        print(f"{PROG}: {path}: cannot write ({e.strerror or e})", file=sys.stderr)
        try:
            os.unlink(tmp)
        except OSError:
            pass
        sys.exit(1)


def openmp_loaded():
    """Whether an OpenMP runtime is mapped into this process (Linux), else None."""
    try:
        with open("/proc/self/maps", encoding="utf-8") as f:
            maps = f.read()
    except OSError:
        return None
    return any(lib in maps for lib in ("libgomp", "libomp", "libiomp"))


def stats_ms(np, seconds):
    a = np.asarray(seconds) * 1e3
    if a.size == 0:
        return {"median": None, "mean": None, "total": 0.0}
    return {"median": float(np.median(a)), "mean": float(a.mean()), "total": float(a.sum())}


def main(argv):
    args = parse_args(argv)
    np, octomap = import_libs()
    from importlib import metadata

    try:
        version = metadata.version("octomap-python")
    except metadata.PackageNotFoundError:
        version = "unknown"
    res = args.resolution
    try:
        points, offsets, origins, max_range, z_shift, win, cylinders = load_input(np, args.dir, res)
    except BadInput as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 2

    k_revs = len(origins)
    print(f"{PROG}: {k_revs} revolutions, {len(points)} points, resolution {res} m, "
          f"OctoMap via octomap-python {version}", file=sys.stderr)

    def revolution(k):
        pk = points[offsets[k]:offsets[k + 1]].astype(np.float64)  # the binding wants float64
        pk[:, 2] += z_shift
        ok = origins[k].astype(np.float64)
        ok[2] += z_shift
        return pk, ok

    # 1. Insertion, one insertPointCloud call per revolution.
    tree = octomap.OcTree(res)
    insert_s, insert_cpu_s = [], []
    next_report = 1
    for k in range(k_revs):
        pk, ok = revolution(k)
        c0, t0 = time.process_time(), time.perf_counter()
        tree.insertPointCloud(pk, ok, maxrange=max_range)
        insert_s.append(time.perf_counter() - t0)
        insert_cpu_s.append(time.process_time() - c0)
        tenths = (k + 1) * 10 // k_revs
        if tenths >= next_report:
            print(f"{PROG}: {tenths * 10}% ({k + 1}/{k_revs} revolutions), insertion "
                  f"median {np.median(insert_s) * 1e3:.1f} ms/revolution, {tree.size()} nodes",
                  file=sys.stderr)
            next_report = tenths + 1

    # The binding's Python-level copy of the points, estimated: the same call on a scratch
    # tree with a 1 um maxrange (every ray truncated to nothing), on the largest revolution.
    big = int(np.argmax(np.diff(offsets)))
    pk, ok = revolution(big)
    scratch = octomap.OcTree(res)
    t0 = time.perf_counter()
    scratch.insertPointCloud(pk, ok, maxrange=1e-6)
    copy_ms = (time.perf_counter() - t0) * 1e3
    del scratch, pk

    # 2. The tree.
    memory = int(tree.memoryUsage())
    memory_full = int(tree.memoryFullGrid())
    nodes = int(tree.size())
    leaves = int(tree.getNumLeafNodes())
    t0 = time.perf_counter()
    tree.updateInnerOccupancy()
    uio_ms = (time.perf_counter() - t0) * 1e3

    # 3. Occupied voxels inside the window.
    t0 = time.perf_counter()
    limit = 32768 * res * (1 - 1e-6)
    lo = np.array([win["x0"], win["y0"], FLOOR_Z_M + z_shift]).clip(-limit, limit)
    hi = np.array([win["x1"], win["y1"], win["z_top"] + z_shift]).clip(-limit, limit)
    occ = []
    occupied = tree.isNodeOccupied
    append = occ.append
    for it in tree.begin_leafs_bbx(lo, hi):
        if occupied(it):
            append((it.getX(), it.getY(), it.getZ(), it.getSize()))
    c = expand_leaves(np, occ, res)
    c[:, 2] -= z_shift
    keep = ((c[:, 0] >= win["x0"]) & (c[:, 0] < win["x1"]) & (c[:, 1] >= win["y0"])
            & (c[:, 1] < win["y1"]) & (c[:, 2] >= FLOOR_Z_M) & (c[:, 2] < win["z_top"]))
    c = c[keep]
    c = c[np.lexsort((c[:, 2], c[:, 1], c[:, 0]))].astype(np.float32)
    export_ms = (time.perf_counter() - t0) * 1e3
    write_atomic(args.voxels, lambda f: np.save(f, c))
    print(f"{PROG}: {len(c)} occupied voxels in the window ({len(occ)} occupied leaves "
          f"touching it), {export_ms:.0f} ms", file=sys.stderr)

    # 4. Pose checks.
    check = make_pose_check(np, octomap, tree, res, z_shift, args.query)
    answers, pose_s = [], []
    for cyls in cylinders:
        t0 = time.perf_counter()
        hit = check(cyls)
        pose_s.append(time.perf_counter() - t0)
        answers.append(bool(hit))
    pose_us = np.asarray(pose_s) * 1e6
    print(f"{PROG}: {len(answers)} poses checked ({args.query}), {sum(answers)} collide",
          file=sys.stderr)

    # 5. Report.
    report = {
        "library": "octomap-python",
        "version": version,
        "octomap_version": ".".join(version.split(".")[:3]),
        "resolution_m": float(tree.getResolution()),
        "revolutions": k_revs,
        "points": int(len(points)),
        "insert_ms": {**stats_ms(np, insert_s), "per_revolution": [s * 1e3 for s in insert_s]},
        "insert_cpu_ms": stats_ms(np, insert_cpu_s),
        "insert_options": {"maxrange": max_range, "lazy_eval": False, "discretize": False},
        "binding_copy_ms_estimate": copy_ms,
        "openmp": openmp_loaded(),
        "memory_bytes": memory,
        "memory_full_grid_bytes": memory_full,
        "nodes": nodes,
        "leaves": leaves,
        "tree_depth": int(tree.getTreeDepth()),
        "update_inner_occupancy_ms": uio_ms,
        "prune_ms": None,
        "prune_note": "the binding has no OcTree.prune(); with lazy_eval=False OctoMap prunes "
                      "during insertion",
        "z_shift_m": z_shift,
        "floor_z_m": FLOOR_Z_M,
        "window": win,
        "occupied_voxels_exported": int(len(c)),
        "export_ms": export_ms,
        "pose_check_us": {
            "median": float(np.median(pose_us)) if len(pose_us) else None,
            "mean": float(pose_us.mean()) if len(pose_us) else None,
            "per_pose": [float(u) for u in pose_us],
        },
        "pose_answers": answers,
        "query_method": f"{args.query}: {QUERY_METHODS[args.query]}",
    }
    text = json.dumps(report, indent=1) + "\n"
    write_atomic(args.out, lambda f: f.write(text.encode()))
    print(f"{PROG}: wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
