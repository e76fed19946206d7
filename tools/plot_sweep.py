#!/usr/bin/env python3
"""Overlay plots of a grainlab sweep: q-eps1 and eps_v-eps1 of every completed case.

Usage: plot_sweep.py SWEEP_DIR   (reads SWEEP_DIR/sweep.csv and each case's timeseries.csv)

A sweep with replicate seeds (--seeds N, recorded in sweep.json) draws one curve per case of the
other keys: the mean over its seeds on a common strain grid, and a band from the lowest to the
highest seed (the spread). A simple-shear sweep plots against gamma."""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_series(path, strain, column, scale):
    with open(path, newline="") as f:
        data = list(csv.DictReader(f))
    if not data or strain not in data[0] or column not in data[0]:
        return None
    x = np.array([float(d[strain]) for d in data])
    y = np.array([scale * float(d[column]) if d[column] else np.nan for d in data])
    return 100.0 * x, y


def main(directory):
    with open(os.path.join(directory, "sweep.csv"), newline="") as f:
        reader = csv.DictReader(f)
        # Columns: case, status, the varied keys, then the macro-parameters starting at e0.
        varied = reader.fieldnames[2:reader.fieldnames.index("e0")]
        rows = [r for r in reader if r["status"] == "completed"]
    seeds = 1
    try:
        with open(os.path.join(directory, "sweep.json")) as f:
            seeds = int(json.load(f).get("seeds", 1))
    except (OSError, ValueError, TypeError):
        pass
    grouped = seeds > 1 and "sample.seed" in varied
    keys = [k for k in varied if not (grouped and k == "sample.seed")]
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in keys), []).append(r)
    out = os.path.join(directory, "plots")
    os.makedirs(out, exist_ok=True)
    first = next((os.path.join(directory, r["case"], "timeseries.csv") for r in rows), None)
    strain = "eps1"
    if first and os.path.exists(first):
        with open(first, newline="") as f:
            header = next(csv.reader(f), [])
        if "gamma" in header:
            strain = "gamma"
    xlabel = "shear strain gamma [%]" if strain == "gamma" else "axial strain eps1 [%]"
    panels = [("q", 1e-3, "deviator stress q [kPa]", "q_eps1.png"),
              ("eps_v", 100.0, "volumetric strain eps_v [%] (contraction +)", "epsv_eps1.png")]
    if strain == "gamma":
        panels[0] = ("tau", 1e-3, "shear stress tau [kPa]", "q_eps1.png")
    for column, scale, label, name in panels:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for values, members in groups.items():
            legend = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in zip(keys, values)) or "base"
            curves = []
            for r in members:
                path = os.path.join(directory, r["case"], "timeseries.csv")
                if os.path.exists(path):
                    c = read_series(path, strain, column, scale)
                    if c is not None:
                        curves.append(c)
            if not curves:
                continue
            if not grouped:
                for x, y in curves:
                    ax.plot(x, y, lw=1.2, label=legend)
                continue
            # The common grid: up to the shortest seed's end, so every point has every seed.
            end = min(x[-1] for x, _ in curves)
            grid = np.linspace(0.0, end, 400)
            ys = np.array([np.interp(grid, x, y) for x, y in curves])
            line, = ax.plot(grid, np.nanmean(ys, axis=0), lw=1.4,
                            label=f"{legend} (mean of {len(curves)} seeds)")
            ax.fill_between(grid, np.nanmin(ys, axis=0), np.nanmax(ys, axis=0), color=line.get_color(), alpha=0.2,
                            lw=0)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        if grouped:
            ax.set_title("band: lowest to highest seed", fontsize=8)
        fig.tight_layout()
        tmp = os.path.join(out, name + ".tmp.png")
        fig.savefig(tmp, dpi=110)
        plt.close(fig)
        os.replace(tmp, os.path.join(out, name))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
