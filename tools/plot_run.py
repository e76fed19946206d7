#!/usr/bin/env python3
"""Plots of one grainlab results folder: q-eps1, eps_v-eps1, phi-eps1, e-eps1 (PNG in DIR/plots).

Usage: plot_run.py DIR
Reads DIR/timeseries.csv (and DIR/summary.json for the annotations). Signs as in PHYSICS.md §0:
compression positive, eps_v > 0 in contraction (dilation plots downward)."""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    """A CSV cell as a float; an empty cell is a value that could not be measured (NaN, not 0)."""
    return float(text) if text not in ("", None) else float("nan")


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [number(r[k]) for r in rows] for k in rows[0]} if rows else {}


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def main(directory):
    data = read_columns(os.path.join(directory, "timeseries.csv"))
    if len(data.get("eps1", [])) < 2:
        return 0
    summary = {}
    try:
        with open(os.path.join(directory, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        pass
    out = os.path.join(directory, "plots")
    os.makedirs(out, exist_ok=True)
    eps1 = [100.0 * v for v in data["eps1"]]
    title = "e0 = {:.3f}, p = {:.0f} kPa, N = {}".format(
        summary.get("e0", float("nan")), summary.get("confining_pressure", 0) / 1e3,
        summary.get("n_particles", "?"))

    panels = [
        ("q_eps1.png", [v / 1e3 for v in data["q"]], "deviator stress q [kPa]"),
        ("epsv_eps1.png", [100.0 * v for v in data["eps_v"]], "volumetric strain eps_v [%] (contraction +)"),
        ("phi_eps1.png", data["phi_deg"], "mobilised friction angle phi [deg]"),
        ("e_eps1.png", data["e"], "void ratio e"),
    ]
    for name, y, label in panels:
        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.plot(eps1, y, lw=1.4)
        ax.set_xlabel("axial strain eps1 [%]")
        ax.set_ylabel(label)
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        if name == "phi_eps1.png" and "phi_peak_deg" in summary:
            ax.axhline(summary["phi_peak_deg"], color="C3", ls="--", lw=0.8,
                       label="phi_p = {:.1f} deg".format(summary["phi_peak_deg"]))
            ax.axhline(summary["phi_res_deg"], color="C2", ls=":", lw=0.8,
                       label="phi_res = {:.1f} deg".format(summary["phi_res_deg"]))
            ax.legend(fontsize=8)
        if name == "epsv_eps1.png":
            ax.axhline(0.0, color="k", lw=0.5)
        fig.tight_layout()
        save(fig, os.path.join(out, name))

    # One overview sheet with the four curves.
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    for ax, (name, y, label) in zip(axes.flat, panels):
        ax.plot(eps1, y, lw=1.2)
        ax.set_xlabel("eps1 [%]")
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save(fig, os.path.join(out, "overview.png"))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
