#!/usr/bin/env python3
"""A stress path the command line does not have, scripted step by step (like a YADE script):
compression at constant mean stress p, then a stress reversal (the axial strain rate reversed until
the deviator has fallen back through zero into extension), on a small prepared sample.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/custom_stress_path.py [OUT.png]

Writes a PNG (default runs/custom-stress-path.png) of q and the volumetric strain against the
axial strain (a few seconds on one thread)."""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

import grainlab

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join("runs", "custom-stress-path.png")
os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
sim = grainlab.Simulation("quick-triaxial", set={"sample.n_particles": 150}, threads=1)
p = sim.p  # the confining pressure the sample was prepared at
rate = sim.inertial_rate(1e-3)  # quasi-static: inertial number 1e-3
sim.reset_reference()
rows = []


def drive(axial_rate, until):
    """Axial strain at `axial_rate`; the lateral walls keep (sigma_x + sigma_y + sigma_z)/3 = p."""
    sim.set_strain_rate(2, axial_rate)
    while not until():
        lateral = max(0.0, 0.5 * (3.0 * p - sim.boundary_stress[2]))
        sim.set_stress(0, lateral)
        sim.set_stress(1, lateral)
        sim.step(5)
        rows.append(sim.state())


drive(rate, lambda: sim.strain[2] >= 0.01)            # compression at constant p to 1 % axial strain
drive(-rate, lambda: sim.q <= -0.3 * p)                # reversal: unload, then extension to q = -0.3 p

eps = [100 * r["eps_z"] for r in rows]
fig, (a, b) = plt.subplots(2, 1, sharex=True, figsize=(6, 6))
a.plot(eps, [r["q"] / 1e3 for r in rows])
a.set_ylabel("q [kPa]")
b.plot(eps, [100 * r["eps_v"] for r in rows])
b.set_ylabel("volumetric strain [%]")
b.set_xlabel("axial strain [%]")
a.set_title(f"constant p = {p / 1e3:.0f} kPa, then reversed ({sim.n_particles} grains)")
fig.tight_layout()
fig.savefig(out, dpi=100)
drift = sorted(abs(r["p"] - p) / p for r in rows)
print(f"{len(rows)} records, q_max = {max(r['q'] for r in rows) / 1e3:.1f} kPa, "
      f"q_min = {min(r['q'] for r in rows) / 1e3:.1f} kPa, |p - p0|/p0: median {100 * drift[len(drift) // 2]:.2f} %, "
      f"95th percentile {100 * drift[int(0.95 * len(drift))]:.2f} %; {out}")
