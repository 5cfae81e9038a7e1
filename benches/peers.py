#!/usr/bin/env python3
"""Peers of the VS-Tree simplification, for `benches/table1`: PyMeshLab's vertex clustering
(`meshing_decimation_clustering`) and quadric edge collapse
(`meshing_decimation_quadric_edge_collapse`), run at a given output size.

Usage (normally called by `cargo bench --bench table1 -- --peers`):

    python3 benches/peers.py --input ../shared/data/igea.ply --target 6800 [--target 2300] \
        --runs 3 --out-dir target/bench-peers --name igea

For every target triangle count it writes `<out-dir>/<name>-<target>-<method>.ply` and prints
one tab-separated line per method on stdout:

    peer <method> <target> <faces> <median seconds> <parameter> <output path>

The Rust bench reads the outputs back and measures their distance to the input with
`vstree::distance`, so every row of the table uses one metric. Only the filter call is timed
(the mesh is already in memory), as for the Rust side. Diagnostics go to stderr.

PyMeshLab runs from a virtual environment under `target/bench-venv`, created on first use with
a pinned version; missing system libraries (libGL and friends) are installed with apt-get when
possible (see `benches/bench_venv.py`). Set `PEERS_NO_SETUP=1` to skip the set-up and use
whatever `python3` has.
"""

import argparse
import statistics
import time
from pathlib import Path

from bench_venv import ROOT, ensure, log

PYMESHLAB = "pymeshlab==2025.7.post1"


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
    args = parser.parse_args()

    ensure(required=[("pymeshlab", PYMESHLAB)])  # re-runs this script in the venv

    import pymeshlab

    args.out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or args.input.stem
    loader = pymeshlab.MeshSet()
    loader.load_new_mesh(str(args.input))
    base = loader.current_mesh()
    log(f"{name}: {base.vertex_number()} vertices, {base.face_number()} faces")

    for target in args.target:
        cell = clustering_cell(base, target)
        seconds, ms = timed_decimate(
            base,
            "meshing_decimation_clustering",
            args.runs,
            threshold=pymeshlab.PercentageValue(cell),
        )
        report(ms, "meshlab-clustering", target, seconds, f"cell={cell:.4g}%", args.out_dir, name)

        seconds, ms = timed_decimate(
            base, "meshing_decimation_quadric_edge_collapse", args.runs, targetfacenum=target
        )
        report(ms, "meshlab-qec", target, seconds, "defaults", args.out_dir, name)


def report(ms, method, target, seconds, parameter, out_dir, name):
    path = out_dir / f"{name}-{target}-{method}.ply"
    ms.save_current_mesh(
        str(path), binary=True, save_vertex_normal=False, save_vertex_color=False
    )
    faces = ms.current_mesh().face_number()
    print(f"peer\t{method}\t{target}\t{faces}\t{seconds:.6f}\t{parameter}\t{path}", flush=True)


if __name__ == "__main__":
    main()
