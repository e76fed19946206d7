#!/usr/bin/env python3
"""Reading a results folder back: the summary, the time series and the VTK snapshots (meshio).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/read_results.py [RESULTS_FOLDER]

Without a folder, first makes one: a short run with VTK snapshots (about 10 s)."""
import os
import sys

import meshio
import numpy as np

import grainlab

if len(sys.argv) > 1:
    result = grainlab.Result(sys.argv[1])
else:
    result = grainlab.run("quick-triaxial", out=os.path.join("runs", "read-results"), threads=1,
                          set={"sample.n_particles": 150, "test.final_axial_strain": 0.005,
                               "output.vtk_every_strain": 0.0025, "output.plots": False})

s = result.summary
print(f"{result.folder}: {s['status']}, {s['n_particles']} grains, e0 = {s['e0']:.4f}, "
      f"phi_peak = {s.get('phi_peak_deg')} deg")
ts = result.timeseries
print(f"time series: {len(ts)} records, columns {', '.join(ts.dtype.names[:8])}, ...")
print(f"  final: eps1 = {ts['eps1'][-1]:.4f}, q = {ts['q'][-1] / 1e3:.1f} kPa, e = {ts['e'][-1]:.4f}")
particles = [f for f in result.vtk if os.path.basename(f).startswith("particles_")]
for path in particles:
    mesh = meshio.read(path)
    radius = mesh.point_data["radius"] if "radius" in mesh.point_data else None
    print(f"  {os.path.basename(path)}: {len(mesh.points)} grains, centre of mass "
          f"{np.round(mesh.points.mean(axis=0), 5)}, fields {', '.join(sorted(mesh.point_data))}"
          + (f", mean radius {radius.mean():.5f} m" if radius is not None else ""))
if result.plots:
    print("plots:", ", ".join(os.path.basename(p) for p in result.plots))
