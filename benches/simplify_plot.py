#!/usr/bin/env python3
"""Pictures for `benches/simplify`, from the two tables it wrote:

- the curve (tab-separated: model, method, ratio, triangles, chamfer, hausdorff, seconds): per
  model, the Chamfer distance to the input (relative to its diagonal) against the output's
  triangle count, log-log, one line per method, into `<out-dir>/simplify-rd-<model>.png`;
- the times at one ratio over every model (model, method, ratio, input_triangles, seconds): the time
  of each method's call against the input's triangle count, log-log, with a least-squares
  power law per method (its exponent in the legend: 1 is linear), into
  `<out-dir>/simplify-time-size.png`.

Usage (normally called by `cargo bench --bench simplify`):

    python3 benches/simplify_plot.py target/bench-simplify/curve.tsv \\
        target/bench-simplify/times.tsv docs/images

Prints one line per picture written on stdout. matplotlib runs from the pinned virtual
environment of the peers (`benches/bench_venv.py`).
"""

import csv
import math
import re
import sys
from collections import defaultdict
from pathlib import Path

from bench_venv import ensure, log

MATPLOTLIB = "matplotlib==3.11.2"
# The new mode first and boldest; every method keeps its colour and marker in every picture.
STYLE = {
    "vstree sized, topology kept": ("tab:red", "o", 2.4),
    "vstree sized, topology kept (1 thread)": ("salmon", "o", 1.2),
    "vstree VS-Tree clustering": ("tab:orange", "s", 1.2),
    "vstree octree clustering": ("tab:brown", "D", 1.2),
    "vstree streamed (plain)": ("gold", "h", 1.2),
    "meshopt-simplify": ("tab:blue", "^", 1.8),
    "meshopt-sloppy": ("tab:cyan", "v", 1.2),
    "fast-simplification": ("tab:green", "P", 1.2),
    "meshlab-qec": ("tab:purple", "X", 1.2),
    "meshlab-clustering": ("tab:gray", "*", 1.2),
}


def style_order(method):
    return list(STYLE).index(method) if method in STYLE else len(STYLE)


def slug(model):
    """A file-name part for a model's name: "cheese x1024 (14M)" gives "cheese-x1024-14M"."""
    return re.sub(r"[^A-Za-z0-9_.]+", "-", model).strip("-")


def read(path):
    with Path(path).open() as f:
        return list(csv.DictReader(f, delimiter="\t"))


def error_against_size(plt, rows, out_dir):
    curves = defaultdict(lambda: defaultdict(list))
    for row in rows:
        chamfer = float(row["chamfer"])
        if chamfer == chamfer and chamfer > 0:  # not NaN
            curves[row["model"]][row["method"]].append((int(row["triangles"]), chamfer))
    for model, methods in curves.items():
        fig, ax = plt.subplots(figsize=(7, 5), dpi=110)
        for method in sorted(methods, key=style_order):
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
        path = out_dir / f"simplify-rd-{slug(model)}.png"
        fig.savefig(path)
        plt.close(fig)
        log(f"wrote {path}")
        print(f"plot\t{path.name}", flush=True)


def power_law(points):
    """Least-squares fit of log(seconds) = k log(triangles) + c: (k, c), or None below 2 sizes."""
    xs = [math.log(x) for x, _ in points]
    ys = [math.log(y) for _, y in points]
    if len(set(xs)) < 2:
        return None
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    k = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return k, my - k * mx


def time_against_size(plt, rows, out_dir):
    series = defaultdict(list)
    ratios = {float(row["ratio"]) for row in rows}
    for row in rows:
        seconds = float(row["seconds"])
        if seconds > 0:
            series[row["method"]].append((int(row["input_triangles"]), seconds))
    if not series:
        return
    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=110)
    for method in sorted(series, key=style_order):
        points = sorted(series[method])
        colour, marker, width = STYLE.get(method, ("black", ".", 1.0))
        fit = power_law(points)
        label = method if fit is None else f"{method} (exponent {fit[0]:.2f})"
        ax.scatter([p[0] for p in points], [p[1] for p in points], color=colour, marker=marker, s=18, label=label)
        if fit is not None:
            k, c = fit
            ends = [points[0][0], points[-1][0]]
            ax.plot(ends, [math.exp(c) * x**k for x in ends], color=colour, linewidth=width, alpha=0.7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("input triangles")
    ax.set_ylabel("time of the call (s)")
    to = ", ".join(f"{100 * r:g}%" for r in sorted(ratios))
    ax.set_title(f"time against input size, every model simplified to {to} of its triangles")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = out_dir / "simplify-time-size.png"
    fig.savefig(path)
    plt.close(fig)
    log(f"wrote {path}")
    print(f"plot\t{path.name}", flush=True)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    ensure(required=[("matplotlib", MATPLOTLIB)])  # re-runs this script in the venv
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(sys.argv[3])
    out_dir.mkdir(parents=True, exist_ok=True)
    error_against_size(plt, read(sys.argv[1]), out_dir)
    time_against_size(plt, read(sys.argv[2]), out_dir)


if __name__ == "__main__":
    main()
