# -*- coding: utf-8 -*-
"""YADE peer of `grainlab bench triaxial-iso`: the same packing, law and servo, timed.

Usage:
    yade -n -j THREADS -x bench/peer/yade_bench.py PACKING --steps S [--dt DT] [--warmup 200] [--periodic]

PACKING is the scene's cached grainlab packing file (~/.cache/grainlab/triaxial-iso-N.txt, format 2
or 1, read by packing_file.py: the six wall planes and the spheres). --dt is grainlab's
time step for the same sample (printed by `grainlab bench --json`); without it 0.5 PWaveTimeStep().

The scene of the grainlab bench: Ec = 30 GPa, ks/kn = 0.3, mu = 30 deg, contact moments with
beta = 0.15 and eta = 1 (YADE's CohFrictMat, alphaKr = alphaKtw = beta, etaRoll = etaTwist = eta,
momentRotationLaw, always_use_moment_law, useIncrementalForm), rho = 2600 kg/m3, Cundall damping
0.3, no gravity, six frictionless rigid walls (Box bodies) all servo-controlled at 100 kPa by
TriaxialStressController. YADE caps the bending moment by eta * min(R1, R2) * Fn where grainlab
uses eta * (R1 + R2) / 2 * Fn: below the cap both are the same elastic law, and in an isotropically
compressed sample almost no contact reaches it, so the work per step is the same.

With --periodic, PACKING is a packing of a periodic cell (format 2): YADE's periodic cell
(O.periodic, O.cell.hSize from the file) held at the pressure by PeriTriaxController, as
bench/peer/yade_periodic.py sets it up; no walls.

Prints one JSON line: scene, n_particles, n_contacts, steps, seconds, particle_steps_per_s, threads.
"""

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: the script's folder
from yade import O, utils  # noqa: E402
from yade.wrapper import TriaxialStressController  # noqa: E402
import yade_scene  # noqa: E402

parser = argparse.ArgumentParser(prog='yade -n -x yade_bench.py')
parser.add_argument('packing')
parser.add_argument('--steps', type=int, default=2000)
parser.add_argument('--warmup', type=int, default=200)
parser.add_argument('--dt', type=float, default=None)
parser.add_argument('--pressure', type=float, default=100e3)
parser.add_argument('--periodic', action='store_true')
args = parser.parse_args(sys.argv[1:])

if args.periodic:
    from yade.minieigenHP import Vector3  # Debian yade 2023: no separate minieigen
    from yade.wrapper import PeriTriaxController
    spheres = yade_scene.build_periodic(args.packing)
    O.engines = yade_scene.periodic_engines(PeriTriaxController(
        goal=Vector3(-args.pressure, -args.pressure, -args.pressure), stressMask=7,
        maxStrainRate=Vector3(1.0, 1.0, 1.0), maxUnbalanced=1e-3))
    firstSphere = 0
else:
    planes, spheres = yade_scene.read_packing(args.packing)
    thick = yade_scene.build(planes, spheres)
    O.engines = yade_scene.engines(TriaxialStressController(
        internalCompaction=False, thickness=thick, wall_left_id=0, wall_right_id=1, wall_bottom_id=2,
        wall_top_id=3, wall_back_id=4, wall_front_id=5, stressMask=7, goal1=-args.pressure,
        goal2=-args.pressure, goal3=-args.pressure, max_vel=1.0))
    firstSphere = 6
O.dt = args.dt if args.dt else 0.5 * utils.PWaveTimeStep()

O.run(args.warmup, True)
t0 = time.time()
O.run(args.steps, True)
seconds = time.time() - t0
contacts = sum(1 for i in O.interactions  # sphere-sphere, as grainlab counts them
               if i.isReal and i.id1 >= firstSphere and i.id2 >= firstSphere and i.phys.normalForce.norm() > 0)
print(json.dumps({"scene": "triaxial-iso-periodic" if args.periodic else "triaxial-iso", "program": "yade", "n_particles": len(spheres),
                  "n_contacts": contacts, "steps": args.steps, "seconds": seconds,
                  "particle_steps_per_s": args.steps * len(spheres) / seconds,
                  "threads": O.numThreads, "dt": O.dt}))
sys.stdout.flush()
os._exit(0)  # YADE's interpreter would otherwise stay open after -x on some builds
