"""`fovea gaze plot`: gaze angles against time and the scanpath on the screen, from the data
file {"figure": "gaze", ...} the command writes next to the figure.

Fields: file (stem), source, width_px (of the PNG), screen {width, height, fov_x_deg, fov_y_deg}, sample_period_s,
stride (every stride-th sample kept), t (s), h and v (deg; null: untracked), x and y (px;
null: off the screen or untracked), saccade (1 in an I-VT saccade), saccades and untracked
([[t0, t1], ...] in s)."""
import fovea_plot as fp
from fovea_plot import plt


def broken(t, v, period):
    """Lines break at untracked samples (null) and where time jumps by more than 5 sample
    periods of the recording (a gap: a 2-hour gap is not a 2-hour drift)."""
    if period <= 0:
        return fp.break_gaps(t, [fp.num(a) for a in v])
    xs, ys = [], []
    for i, (a, b) in enumerate(zip(t, v)):
        if i and a - t[i - 1] > 5 * period:
            xs.append(float("nan"))
            ys.append(float("nan"))
        xs.append(a)
        ys.append(fp.num(b))
    return xs, ys


def draw(d, data_path):
    sc = d["screen"]
    t = d["t"]
    period = d.get("sample_period_s", 0) * d.get("stride", 1)
    width = d.get("width_px", 1500) / fp.matplotlib.rcParams["savefig.dpi"]
    fig = plt.figure(figsize=(width, 1.1 * width))
    grid = fig.add_gridspec(3, 1, height_ratios=[1, 1, 1.8], hspace=0.45)
    axes = [fig.add_subplot(grid[0]), fig.add_subplot(grid[1])]
    axes[1].sharex(axes[0])
    for ax, key, name, unit, colour in ((axes[0], "h", "horizontal gaze angle", "deg, + right", "C0"),
                                        (axes[1], "v", "vertical gaze angle", "deg, + up", "C2")):
        for i, (a, b) in enumerate(d["saccades"]):
            ax.axvspan(a, b, color="C3", alpha=0.25, linewidth=0, label="saccade (I-VT)" if i == 0 else None)
        for i, (a, b) in enumerate(d["untracked"]):
            ax.axvspan(a, b, color="0.5", alpha=0.3, linewidth=0, label="untracked" if i == 0 else None)
        xs, ys = broken(t, d[key], period)
        ax.plot(xs, ys, color=colour, linewidth=0.9, label=name, gid=f"gaze-{key}")
        ax.axhline(0, color="black", linewidth=0.6, alpha=0.5)
        ax.set_ylabel(f"{name.split()[0]} ({unit})")
        fp.legend(ax, 3)
    axes[1].set_xlabel("time from the first sample (s)")
    axes[0].set_title(f"{d.get('source', '')}: gaze angles (lines broken at untracked samples and gaps)", fontsize=10)

    ax = fig.add_subplot(grid[2])
    fix_x = [x for x, y, s in zip(d["x"], d["y"], d["saccade"]) if x is not None and y is not None and not s]
    fix_y = [y for x, y, s in zip(d["x"], d["y"], d["saccade"]) if x is not None and y is not None and not s]
    sx, sy = [], []  # saccade paths, broken between saccades
    for i in range(1, len(t)):
        if d["saccade"][i] and None not in (d["x"][i - 1], d["x"][i], d["y"][i - 1], d["y"][i]):
            sx += [d["x"][i - 1], d["x"][i], float("nan")]
            sy += [d["y"][i - 1], d["y"][i], float("nan")]
    ax.scatter(fix_x, fix_y, s=3, color="navy", alpha=0.25, linewidths=0, label="fixation sample")
    ax.plot(sx, sy, color="C3", linewidth=0.8, alpha=0.7, label="saccade path")
    ax.set_xlim(0, sc["width"])
    ax.set_ylim(sc["height"], 0)  # screen rows grow downwards
    ax.set_aspect("equal")
    ax.set_xlabel("screen x (px)")
    ax.set_ylabel("screen y (px)")
    ax.set_title(f"scanpath on the screen, {sc['width']}x{sc['height']} px, "
                 f"{sc['fov_x_deg']:.1f}x{sc['fov_y_deg']:.1f} deg", fontsize=10)
    fp.legend(ax, 2)
    fp.save(fig, fp.out_stem(data_path, d["file"]))


fp.main(draw)
