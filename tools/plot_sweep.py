#!/usr/bin/env python3
"""Overlay plots of a grainlab sweep: q-eps1 and eps_v-eps1 of every completed case.

Usage: plot_sweep.py SWEEP_DIR   (reads SWEEP_DIR/sweep.csv and each case's timeseries.csv)"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(directory):
    with open(os.path.join(directory, "sweep.csv"), newline="") as f:
        reader = csv.DictReader(f)
        # Columns: case, status, the varied keys, then the macro-parameters starting at e0.
        varied = reader.fieldnames[2:reader.fieldnames.index("e0")]
        rows = [r for r in reader if r["status"] == "completed"]
    out = os.path.join(directory, "plots")
    os.makedirs(out, exist_ok=True)
    panels = [("q", 1e-3, "deviator stress q [kPa]", "q_eps1.png"),
              ("eps_v", 100.0, "volumetric strain eps_v [%] (contraction +)", "epsv_eps1.png")]
    for column, scale, label, name in panels:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for r in rows:
            path = os.path.join(directory, r["case"], "timeseries.csv")
            if not os.path.exists(path):
                continue
            with open(path, newline="") as f:
                data = list(csv.DictReader(f))
            legend = ", ".join(f"{k.split('.')[-1]}={r[k]}" for k in varied)
            ax.plot([100 * float(d["eps1"]) for d in data], [scale * (float(d[column]) if d[column] else float("nan")) for d in data],
                    lw=1.2, label=legend)
        ax.set_xlabel("axial strain eps1 [%]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
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
