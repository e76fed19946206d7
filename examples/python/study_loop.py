#!/usr/bin/env python3
"""A small parameter study with grainlab.run in a plain loop: the rolling stiffness beta of the
contact moments ([W] §4.4, beta = 0 switches the moments off), one short triaxial test each, and
their stress-strain curves overlaid.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/study_loop.py [OUT_FOLDER]

Writes OUT_FOLDER/beta_*/ (each a results folder) and OUT_FOLDER/study.png (about 30 s)."""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

import grainlab

folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join("runs", "study-loop")
base = grainlab.load_config("quick-triaxial", set={"sample.n_particles": 150, "test.final_axial_strain": 0.02,
                                                   "output.plots": False})
fig, ax = plt.subplots(figsize=(6, 4))
for beta in [0.0, 0.15]:
    result = grainlab.run(base.with_overrides({"contact.beta": beta}), out=os.path.join(folder, f"beta_{beta}"),
                          threads=1)
    ts = result.timeseries
    ax.plot(100 * ts["eps1"], ts["q"] / 1e3, label=f"beta = {beta}: phi_peak = {result.summary['phi_peak_deg']:.1f} deg")
    print(f"beta = {beta}: phi_peak = {result.summary['phi_peak_deg']:.2f} deg, e0 = {result.summary['e0']:.3f}")
ax.set_xlabel("axial strain [%]")
ax.set_ylabel("q [kPa]")
ax.legend()
fig.tight_layout()
fig.savefig(os.path.join(folder, "study.png"), dpi=100)
print(os.path.join(folder, "study.png"))
