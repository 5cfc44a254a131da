"""Shared by the figure scripts of `fovea` (docs/figures.md): matplotlib set up headless and
reproducible, atomic PNG + SVG output, and lines broken where the data has gaps.

Each script reads one data file a command wrote (JSON, next to the figures) and writes
every figure it describes as STEM.png and STEM.svg. Exit status 3: matplotlib is missing."""
import json
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # headless: no display needed
    import matplotlib.pyplot as plt
except ImportError as e:
    print(f"fovea plot: matplotlib is not available ({e}); install python3-matplotlib", file=sys.stderr)
    sys.exit(3)

# Reproducible files: fixed SVG ids, no dates.
matplotlib.rcParams.update({
    "svg.hashsalt": "fovea",
    "svg.fonttype": "none",  # text stays text: searchable, editable in a paper
    "font.size": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "legend.framealpha": 0.9,
    "figure.dpi": 100,
    "savefig.dpi": 150,
})
FORMATS = ("png", "svg")


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def out_stem(data_path, stem):
    """A figure's stem, relative to the data file's folder unless absolute."""
    return stem if os.path.isabs(stem) else os.path.join(os.path.dirname(os.path.abspath(data_path)), stem)


def save(fig, stem):
    """Writes STEM.png and STEM.svg, each to a temporary name first, then renamed."""
    for ext in FORMATS:
        tmp = f"{stem}.tmp.{ext}"
        meta = {"Date": None} if ext == "svg" else {"Software": None}
        fig.savefig(tmp, format=ext, bbox_inches="tight", metadata=meta)
        os.replace(tmp, f"{stem}.{ext}")
    plt.close(fig)


def num(v):
    """JSON null (no value) as NaN, which matplotlib leaves undrawn."""
    return math.nan if v is None else float(v)


def break_gaps(xs, ys, factor=5.0):
    """A NaN between neighbours further apart in x than `factor` times the median step, so a
    line is not drawn across a gap in the recording (a 2-hour gap is not a 2-hour drift)."""
    steps = sorted(b - a for a, b in zip(xs, xs[1:]) if b > a)
    if not steps:
        return list(xs), list(ys)
    limit = factor * steps[len(steps) // 2]
    ox, oy = [], []
    for i, (x, y) in enumerate(zip(xs, ys)):
        if i and x - xs[i - 1] > limit:
            ox.append(math.nan)
            oy.append(math.nan)
        ox.append(x)
        oy.append(y)
    return ox, oy


def legend(ax, entries):
    """Inside the figure: in the axes where it fits, under them when there are many entries."""
    if entries <= 0:
        return
    if entries > 5:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize="small")
    else:
        ax.legend(loc="best", fontsize="small")


def main(draw):
    """Runs draw(data, data_path) for each data file named on the command line."""
    if len(sys.argv) < 2:
        print(f"usage: {os.path.basename(sys.argv[0])} DATA.json...", file=sys.stderr)
        sys.exit(2)
    for path in sys.argv[1:]:
        draw(load(path), path)
