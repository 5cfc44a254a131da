"""Line and scatter charts (latency distributions and sweeps, the sweep report's Pareto,
budget, band and latency plots) from a data file with {"figure": "charts", "charts": [...]}.

A chart: file (stem), title, note, x_label, y_label, series. A series: label, points
[[x, y], ...] (y null: no value, the line breaks), line, markers, step (a CDF), gaps (break
the line where x jumps), emphasised (per point: ringed, e.g. a Pareto front), point_labels
(text next to each point, e.g. the budget or n), vlines (x positions of vertical marks),
hline (a constant y), color (index; shared by series that belong together)."""
import fovea_plot as fp
from fovea_plot import plt


def draw_series(ax, s, colour):
    xs = [fp.num(p[0]) for p in s["points"]]
    ys = [fp.num(p[1]) for p in s["points"]]
    label = s.get("label") or None
    if "hline" in s:
        ax.axhline(s["hline"], color=colour, linestyle="--", linewidth=1, label=label)
        return
    if "vlines" in s:
        for i, x in enumerate(s["vlines"]):
            ax.axvline(x, color=colour, linewidth=0.8, alpha=0.6, label=label if i == 0 else None)
        return
    if s.get("gaps"):
        xs, ys = fp.break_gaps(xs, ys)
    if s.get("line"):
        ax.plot(xs, ys, color=colour, linewidth=1.4, drawstyle="steps-post" if s.get("step") else "default",
                marker="o" if s.get("markers") else None, markersize=4, label=label)
        label = None
    elif s.get("markers"):
        ax.scatter(xs, ys, color=colour, s=18, alpha=0.8, label=label, zorder=3)
    emph = s.get("emphasised") or []
    ex = [x for x, e in zip(xs, emph) if e]
    ey = [y for y, e in zip(ys, emph) if e]
    if ex:
        ax.scatter(ex, ey, s=70, facecolors="none", edgecolors="black", linewidths=1.2, zorder=4)
    for x, y, t in zip(xs, ys, s.get("point_labels") or []):
        if t and x == x and y == y:
            ax.annotate(t, (x, y), textcoords="offset points", xytext=(5, 4), fontsize=7, color=colour)


def draw_chart(c, data_path):
    fig, ax = plt.subplots(figsize=(9, 5.4))
    entries = 0
    for s in c["series"]:
        draw_series(ax, s, f"C{s.get('color', 0) % 10}")
        entries += bool(s.get("label"))
    title = c.get("title", "")
    if c.get("note"):
        title += "\n" + c["note"]
    ax.set_title(title, fontsize=10)
    ax.set_xlabel(c.get("x_label", ""))
    ax.set_ylabel(c.get("y_label", ""))
    fp.legend(ax, entries)
    fp.save(fig, fp.out_stem(data_path, c["file"]))


def draw(data, data_path):
    for c in data["charts"]:
        draw_chart(c, data_path)


fp.main(draw)
