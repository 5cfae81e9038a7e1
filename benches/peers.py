#!/usr/bin/env python3
"""Peers of the VS-Tree simplification, for `benches/table1` and `benches/simplify`:
PyMeshLab's vertex clustering (`meshing_decimation_clustering`) and quadric edge collapse
(`meshing_decimation_quadric_edge_collapse`), and with `--methods` also meshoptimizer's
`simplify` and `simplify_sloppy` and fast-simplification, run at a given output size.

Usage (normally called by `cargo bench --bench table1 -- --peers` or `cargo bench --bench
simplify`):

    python3 benches/peers.py --input ../shared/data/igea.ply --target 6800 [--target 2300] \
        --runs 3 --out-dir target/bench-peers --name igea [--methods meshlab-qec,meshopt-simplify]

For every target triangle count it writes `<out-dir>/<name>-<target>-<method>.ply` and prints
one tab-separated line per method on stdout:

    peer <method> <target> <faces> <median seconds> <parameter> <output path>

(the path is `-` when a method returned no triangle: meshoptimizer's sloppy simplifier on a
tiny target).

The Rust bench reads the outputs back and measures their distance to the input with
`vstree::eval::distance`, so every row of the table uses one metric. Only the filter call is timed
(the mesh is already in memory), as for the Rust side. Diagnostics go to stderr.

Methods: `meshlab-clustering`, `meshlab-qec` (the default pair), `meshopt-simplify`,
`meshopt-sloppy` (meshoptimizer's attribute-free simplifiers, `target_error` 1 so that only the
index count stops them, no options), `fast-simplification` (`target_reduction` from the count).
Every method gets the mesh as PyMeshLab read it, so all start from the same vertices and faces.

The peers run from a virtual environment under `target/bench-venv`, created on first use with
pinned versions; missing system libraries (libGL and friends) are installed with apt-get when
possible (see `benches/bench_venv.py`). Set `PEERS_NO_SETUP=1` to skip the set-up and use
whatever `python3` has.
"""

import argparse
import statistics
import time
from pathlib import Path

from bench_venv import ROOT, ensure, log

PYMESHLAB = "pymeshlab==2025.7.post1"
# meshoptimizer 0.22's C++ (the wrapper's version is its own); built from the sdist, needs g++.
MESHOPTIMIZER = "meshoptimizer==0.2.30a0"
FAST_SIMPLIFICATION = "fast-simplification==0.2.0"
MESHLAB_METHODS = ["meshlab-clustering", "meshlab-qec"]
ARRAY_METHODS = ["meshopt-simplify", "meshopt-sloppy", "fast-simplification"]


def decimate(base, filter_name, **params):
    """Applies a filter to a fresh copy of `base`; returns the resulting MeshSet."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(base)
    getattr(ms, filter_name)(**params)
    return ms


def timed_decimate(base, filter_name, runs, **params):
    """Median time of the filter call alone (the copy into a fresh MeshSet is not timed)."""
    import pymeshlab

    times, ms = [], None
    for _ in range(runs):
        ms = pymeshlab.MeshSet()
        ms.add_mesh(base)
        start = time.perf_counter()
        getattr(ms, filter_name)(**params)
        times.append(time.perf_counter() - start)
    return statistics.median(times), ms


def clustering_cell(base, target):
    """The cell size (percent of the bounding-box diagonal) at which vertex clustering gives
    about `target` faces: bisection in log space, as the face count falls as cells grow."""
    import pymeshlab

    def faces(percent):
        ms = decimate(
            base, "meshing_decimation_clustering", threshold=pymeshlab.PercentageValue(percent)
        )
        return ms.current_mesh().face_number()

    lo, hi = 0.01, 50.0  # percent: fine enough for any target here, coarse enough for a few faces
    best = (float("inf"), hi)
    for _ in range(40):
        mid = (lo * hi) ** 0.5
        count = faces(mid)
        best = min(best, (abs(count - target) / target, mid))
        if abs(count - target) <= 0.01 * target:
            break
        if count > target:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.0005:
            break
    return best[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--input", required=True, type=Path)
    parser.add_argument("--target", required=True, type=int, action="append")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--out-dir", type=Path, default=ROOT / "target" / "bench-peers")
    parser.add_argument("--name", default=None)
    parser.add_argument(
        "--methods",
        default=",".join(MESHLAB_METHODS),
        help="comma-separated, from: " + ", ".join(MESHLAB_METHODS + ARRAY_METHODS),
    )
    args = parser.parse_args()
    methods = args.methods.split(",")
    unknown = [m for m in methods if m not in MESHLAB_METHODS + ARRAY_METHODS]
    if unknown:
        parser.error(f"unknown method(s): {', '.join(unknown)}")

    required = [("pymeshlab", PYMESHLAB)]
    if any(m.startswith("meshopt-") for m in methods):
        required.append(("meshoptimizer", MESHOPTIMIZER))
    if "fast-simplification" in methods:
        required.append(("fast_simplification", FAST_SIMPLIFICATION))
    ensure(required=required)  # re-runs this script in the venv

    import pymeshlab

    args.out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or args.input.stem
    loader = pymeshlab.MeshSet()
    loader.load_new_mesh(str(args.input))
    base = loader.current_mesh()
    log(f"{name}: {base.vertex_number()} vertices, {base.face_number()} faces")

    for target in args.target:
        if "meshlab-clustering" in methods:
            cell = clustering_cell(base, target)
            seconds, ms = timed_decimate(
                base,
                "meshing_decimation_clustering",
                args.runs,
                threshold=pymeshlab.PercentageValue(cell),
            )
            report(ms, "meshlab-clustering", target, seconds, f"cell={cell:.4g}%", args.out_dir, name)
        if "meshlab-qec" in methods:
            seconds, ms = timed_decimate(
                base, "meshing_decimation_quadric_edge_collapse", args.runs, targetfacenum=target
            )
            report(ms, "meshlab-qec", target, seconds, "defaults", args.out_dir, name)
        for method in (m for m in methods if m in ARRAY_METHODS):
            seconds, (vertices, faces), parameter = timed_array_method(
                method, base, target, args.runs
            )
            if len(faces) == 0:  # PyMeshLab cannot hold an empty mesh: no file, path "-"
                print(f"peer\t{method}\t{target}\t0\t{seconds:.6f}\t{parameter}\t-", flush=True)
                continue
            ms = pymeshlab.MeshSet()
            ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces))
            report(ms, method, target, seconds, parameter, args.out_dir, name)


def timed_array_method(method, base, target, runs):
    """Median time of one array-based simplifier's call on `base` (its vertices and faces as
    contiguous arrays of the types the library takes, made before the clock starts), its last
    output as (vertices float64 n x 3, faces int32 m x 3) without unused vertices, and its
    parameters for the record."""
    import numpy as np

    vertices64 = np.ascontiguousarray(base.vertex_matrix(), dtype=np.float64)
    faces = np.ascontiguousarray(base.face_matrix(), dtype=np.int32)
    if method.startswith("meshopt-"):
        import meshoptimizer

        call = meshoptimizer.simplify if method == "meshopt-simplify" else meshoptimizer.simplify_sloppy
        positions = np.ascontiguousarray(vertices64, dtype=np.float32)
        indices = np.ascontiguousarray(faces.reshape(-1), dtype=np.uint32)
        times, out = [], None
        for _ in range(runs):
            destination = np.zeros(indices.size, dtype=np.uint32)
            start = time.perf_counter()
            count = call(destination, indices, positions, target_index_count=3 * target, target_error=1.0)
            times.append(time.perf_counter() - start)
            out = destination[:count].reshape(-1, 3)
        used, remapped = np.unique(out, return_inverse=True)
        result = (vertices64[used], remapped.reshape(-1, 3).astype(np.int32))
        return statistics.median(times), result, "target_error=1"
    import fast_simplification

    reduction = 1.0 - target / max(1, len(faces))
    times, result = [], None
    for _ in range(runs):
        start = time.perf_counter()
        points, triangles = fast_simplification.simplify(vertices64, faces, target_reduction=reduction)
        times.append(time.perf_counter() - start)
        result = (np.asarray(points, dtype=np.float64), np.asarray(triangles, dtype=np.int32))
    return statistics.median(times), result, f"target_reduction={reduction:.4f}"


def report(ms, method, target, seconds, parameter, out_dir, name):
    path = out_dir / f"{name}-{target}-{method}.ply"
    ms.save_current_mesh(
        str(path), binary=True, save_vertex_normal=False, save_vertex_color=False
    )
    faces = ms.current_mesh().face_number()
    print(f"peer\t{method}\t{target}\t{faces}\t{seconds:.6f}\t{parameter}\t{path}", flush=True)


if __name__ == "__main__":
    main()
