"""`fovea density --out`: samples per display pixel as a heat map with a numbered colour bar,
the gaze and the fovea marked, from {"figure": "density", ...} and its .npy array.

Fields: file (stem), array (the .npy next to it: float32 [2, height, width], log10 samples
per pixel (the range's low end where none) and eccentricity in deg), title, gaze_px [x, y], fovea_deg
(the fovea's radius, margin included), range_log10 [lo, hi]."""
import os

import numpy as np

import fovea_plot as fp
from fovea_plot import plt


def draw(d, data_path):
    a = np.load(os.path.join(os.path.dirname(os.path.abspath(data_path)), d["array"]))
    log_spp, ecc = a[0], a[1]
    lo, hi = d["range_log10"]
    h, w = log_spp.shape
    fig, ax = plt.subplots(figsize=(7, 7 * h / w + 1.2))
    im = ax.imshow(np.clip(log_spp, lo, hi), cmap="inferno", vmin=lo, vmax=hi,
                   extent=(0, w, h, 0), interpolation="nearest")
    ax.contour(np.arange(w) + 0.5, np.arange(h) + 0.5, ecc, levels=[d["fovea_deg"]], colors="white", linewidths=1)
    gx, gy = d["gaze_px"]
    ax.plot([gx], [gy], marker="+", color="lime", markersize=14, markeredgewidth=2, linestyle="none", label="gaze")
    ax.plot([], [], color="white", linewidth=1, label=f"fovea edge, {d['fovea_deg']:.1f} deg")
    ax.set_xlabel("display x (px)")
    ax.set_ylabel("display y (px)")
    ax.set_title(d.get("title", ""), fontsize=10)
    ax.grid(False)
    leg = ax.legend(loc="upper right", fontsize="small", facecolor="0.3", labelcolor="white")
    leg.get_frame().set_alpha(0.8)
    ticks = list(range(int(np.ceil(lo)), int(np.floor(hi)) + 1))
    bar = fig.colorbar(im, ax=ax, orientation="horizontal", fraction=0.06, pad=0.1, ticks=ticks)
    bar.ax.set_xticklabels([f"{10.0 ** k:g}" for k in ticks])
    bar.set_label("samples per display pixel (log scale)")
    fp.save(fig, fp.out_stem(data_path, d["file"]))


fp.main(draw)
