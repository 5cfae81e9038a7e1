#!/usr/bin/env python3
"""Error against size for `benches/simplify`: reads the curve it wrote (tab-separated: model,
method, ratio, triangles, chamfer, hausdorff, seconds) and draws, per model, the Chamfer
distance to the input (relative to its diagonal) against the output's triangle count, log-log,
one line per method, into `<out-dir>/simplify-rd-<model>.png`.

Usage (normally called by `cargo bench --bench simplify`):

    python3 benches/simplify_plot.py target/bench-simplify/curve.tsv docs/images

Prints one line per picture written on stdout. matplotlib runs from the pinned virtual
environment of the peers (`benches/bench_venv.py`).
"""

import csv
import sys
from collections import defaultdict
from pathlib import Path

from bench_venv import ensure, log

MATPLOTLIB = "matplotlib==3.11.2"
# The new mode first and boldest; every method keeps its colour and marker in every picture.
STYLE = {
    "vstree sized, topology kept": ("tab:red", "o", 2.4),
    "vstree VS-Tree clustering": ("tab:orange", "s", 1.2),
    "vstree octree clustering": ("tab:brown", "D", 1.2),
    "meshopt-simplify": ("tab:blue", "^", 1.8),
    "meshopt-sloppy": ("tab:cyan", "v", 1.2),
    "fast-simplification": ("tab:green", "P", 1.2),
    "meshlab-qec": ("tab:purple", "X", 1.2),
    "meshlab-clustering": ("tab:gray", "*", 1.2),
}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    ensure(required=[("matplotlib", MATPLOTLIB)])  # re-runs this script in the venv
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    source, out_dir = Path(sys.argv[1]), Path(sys.argv[2])
    curves = defaultdict(lambda: defaultdict(list))
    with source.open() as f:
        for row in csv.DictReader(f, delimiter="\t"):
            chamfer = float(row["chamfer"])
            if chamfer == chamfer and chamfer > 0:  # not NaN
                curves[row["model"]][row["method"]].append((int(row["triangles"]), chamfer))
    out_dir.mkdir(parents=True, exist_ok=True)
    for model, methods in curves.items():
        fig, ax = plt.subplots(figsize=(7, 5), dpi=110)
        for method in sorted(methods, key=lambda m: list(STYLE).index(m) if m in STYLE else 99):
            points = sorted(methods[method])
            colour, marker, width = STYLE.get(method, ("black", ".", 1.0))
            ax.plot(
                [p[0] for p in points],
                [100 * p[1] for p in points],
                color=colour,
                marker=marker,
                linewidth=width,
                markersize=5,
                label=method,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("output triangles")
        ax.set_ylabel("Chamfer distance to the input (% of the diagonal)")
        ax.set_title(f"{model}: error against size")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = out_dir / f"simplify-rd-{model}.png"
        fig.savefig(path)
        plt.close(fig)
        log(f"wrote {path}")
        print(f"plot\t{path.name}", flush=True)


if __name__ == "__main__":
    main()
