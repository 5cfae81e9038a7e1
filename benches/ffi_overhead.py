"""The C ABI through ctypes with numpy, from Python: what a Blender-style host pays around a
1M-triangle simplification (numpy arrays in, numpy arrays out), measured within each run as the
wall time minus the library's own stage times, against the Rust call's median from
benches/ffi_overhead.rs. Run by benches/ffi_overhead.sh."""

import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bindings", "python"))
import vstree  # noqa: E402

RUNS = 15


def main(mesh_path, rust_path):
    source = vstree.load(mesh_path)
    positions, triangles = source.positions, source.triangles  # what a host holds
    source.close()
    print("%6s %9s | %10s %10s %7s" % ("error", "rust ms", "host ms", "host: +ms", "%"))
    for line in open(rust_path):
        error, rust = (float(x) for x in line.split())
        wall, extra = [], []
        for _ in range(RUNS):
            t0 = time.perf_counter()
            result = vstree.simplify(vstree.Mesh(positions, triangles), error=error)
            p, t = result.mesh.positions, result.mesh.triangles
            w = time.perf_counter() - t0
            s = result.stats
            wall.append(w)
            extra.append(w - (s["seconds_samples"] + s["seconds_tree"] + s["seconds_cluster"]))
            del result, p, t
        w, x = statistics.median(wall), statistics.median(extra)
        print("%6.0e %9.1f | %10.1f %10.2f %6.1f%%" % (error, 1e3 * rust, 1e3 * w, 1e3 * x, 100 * x / rust))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
