#!/usr/bin/env python3
"""Peers of the VS-Tree reconstruction, for `benches/table2` and `benches/corpus`: PyMeshLab's
screened Poisson (`generate_surface_reconstruction_screened_poisson`) at depth 8 and 10,
PyMeshLab's ball pivoting (`generate_surface_reconstruction_ball_pivoting`), and Open3D's
Poisson (`TriangleMesh.create_from_point_cloud_poisson`) at depth 8 and 10, plain or with
density trimming (the vertices of the lowest 10% of Open3D's densities removed, for open
scans), on a point cloud with oriented normals.

Usage (normally called by `cargo bench --bench table2 -- --peers` or `--bench corpus`):

    python3 benches/reconstruct_peers.py --input target/bench-table2/igea-cloud.ply \
        --name igea --runs 3 --out-dir target/bench-table2 \
        [--methods meshlab-spsr8,meshlab-spsr10,meshlab-bpa,open3d-poisson10,...]

The input is the cloud with the normals vstree uses (the bench writes it), so every method
sees the same points and normals. For every method it writes `<out-dir>/<name>-<method>.ply`
and prints one tab-separated line on stdout:

    peer <method> <median seconds> <parameters> <output path>

or, for a method that cannot run (Open3D did not install):

    skip <method> <reason>

Poisson runs use all cores (with `OMP_WAIT_POLICY=PASSIVE`: on a loaded machine OpenMP's
spinning threads otherwise make two threads several times slower than one); ball pivoting is
single-threaded. The bench leaves out methods that would take too long on a big cloud.

Only the reconstruction call is timed (the cloud is already in memory), as on the Rust side;
the Rust bench reads the outputs back and measures them with the same code as its own.
Diagnostics go to stderr.

PyMeshLab (required) and Open3D (optional: without it its row is skipped with the reason) run
from the virtual environment `target/bench-venv`, set up by `benches/bench_venv.py` with
pinned versions. Set `PEERS_NO_SETUP=1` to skip the set-up and use whatever `python3` has.
"""

import argparse
import os
import statistics
import time
from pathlib import Path

from bench_venv import ROOT, ensure, log, optional_import

# Read by OpenMP when PyMeshLab or Open3D loads it: wait for work without spinning.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

PYMESHLAB = "pymeshlab==2025.7.post1"
OPEN3D = "open3d-cpu==0.20.0"
METHODS = [
    "meshlab-spsr8",
    "meshlab-spsr10",
    "meshlab-bpa",
    "open3d-poisson8",
    "open3d-poisson10",
    "open3d-poisson8-trim",
    "open3d-poisson10-trim",
]
# Density trimming: the vertices whose Open3D density is below this quantile are removed (and
# their faces), the usual way to open a Poisson surface where the samples end.
TRIM_QUANTILE = 0.10
THREADS = os.cpu_count() or 1


def timed(runs, call):
    """Median seconds of `runs` calls of `call()` (which times itself and returns (seconds,
    result)); returns the median and the last result."""
    times, result = [], None
    for _ in range(runs):
        seconds, result = call()
        times.append(seconds)
    return statistics.median(times), result


def meshlab(base, filter_name, **params):
    """One timed run of a PyMeshLab filter on a fresh copy of the cloud `base` (the copy is not
    timed); returns (seconds, MeshSet)."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(base)
    start = time.perf_counter()
    getattr(ms, filter_name)(**params)
    return time.perf_counter() - start, ms


def save_meshlab(ms, path):
    """Writes the current mesh as binary PLY, positions and faces only."""
    ms.save_current_mesh(
        str(path), binary=True, save_vertex_normal=False, save_vertex_color=False,
        save_vertex_quality=False,
    )


def spsr(base, depth, runs, path):
    """Screened Poisson at `depth`, other parameters at PyMeshLab's defaults, all cores."""
    seconds, ms = timed(
        runs,
        lambda: meshlab(
            base, "generate_surface_reconstruction_screened_poisson", depth=depth, threads=THREADS
        ),
    )
    save_meshlab(ms, path)
    return seconds, f"depth {depth}, {THREADS} threads"


def bpa(base, runs, path):
    """Ball pivoting with PyMeshLab's defaults (radius guessed from the cloud)."""
    seconds, ms = timed(
        runs, lambda: meshlab(base, "generate_surface_reconstruction_ball_pivoting")
    )
    save_meshlab(ms, path)
    return seconds, "auto radius, 1 thread"


def open3d_poisson(o3d, cloud_path, depth, trim, runs, path):
    """Open3D's Poisson at `depth`, other parameters at their defaults, all cores; with `trim`,
    the vertices of the lowest TRIM_QUANTILE of its densities removed (timed too)."""
    cloud = o3d.io.read_point_cloud(str(cloud_path))
    if not cloud.has_normals():
        raise RuntimeError(f"{cloud_path}: no normals read")

    def call():
        start = time.perf_counter()
        mesh, densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(
            cloud, depth=depth, n_threads=-1
        )
        if trim:
            import numpy

            densities = numpy.asarray(densities)
            mesh.remove_vertices_by_mask(densities < numpy.quantile(densities, TRIM_QUANTILE))
        return time.perf_counter() - start, mesh

    seconds, mesh = timed(runs, call)
    o3d.io.write_triangle_mesh(
        str(path), mesh, write_ascii=False, write_vertex_normals=False, write_vertex_colors=False
    )
    trimmed = f", lowest {TRIM_QUANTILE:.0%} of densities removed" if trim else ""
    return seconds, f"depth {depth}{trimmed}, {THREADS} threads"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--input", required=True, type=Path, help="cloud with oriented normals")
    parser.add_argument("--name", default=None, help="prefix of the output files")
    parser.add_argument("--runs", type=int, default=1, help="timed runs per method")
    parser.add_argument("--out-dir", type=Path, default=ROOT / "target" / "bench-table2")
    parser.add_argument(
        "--methods", default=",".join(METHODS), help=f"comma-separated subset of {METHODS}"
    )
    args = parser.parse_args()
    methods = args.methods.split(",")
    unknown = sorted(set(methods) - set(METHODS))
    if unknown:
        parser.error(f"unknown methods: {', '.join(unknown)}")

    optional = [("open3d", OPEN3D)] if any(m.startswith("open3d") for m in methods) else []
    ensure(required=[("pymeshlab", PYMESHLAB)], optional=optional)  # re-runs this in the venv

    import pymeshlab

    args.out_dir.mkdir(parents=True, exist_ok=True)
    name = args.name or args.input.stem
    loader = pymeshlab.MeshSet()
    loader.load_new_mesh(str(args.input))
    base = loader.current_mesh()
    points = base.vertex_number()
    log(f"{name}: {points} points")

    for method in methods:
        path = args.out_dir / f"{name}-{method}.ply"
        log(f"{name}: {method}")
        if method == "meshlab-spsr8":
            seconds, parameters = spsr(base, 8, args.runs, path)
        elif method == "meshlab-spsr10":
            seconds, parameters = spsr(base, 10, args.runs, path)
        elif method == "meshlab-bpa":
            seconds, parameters = bpa(base, args.runs, path)
        else:
            o3d, why = optional_import("open3d", OPEN3D)
            if o3d is None:
                skip(method, f"{OPEN3D} unavailable: {why}")
                continue
            depth = 8 if method.startswith("open3d-poisson8") else 10
            trim = method.endswith("-trim")
            seconds, parameters = open3d_poisson(o3d, args.input, depth, trim, args.runs, path)
        print(f"peer\t{method}\t{seconds:.6f}\t{parameters}\t{path}", flush=True)


def skip(method, reason):
    log(f"skipping {method}: {reason}")
    print(f"skip\t{method}\t{reason}", flush=True)


if __name__ == "__main__":
    main()
