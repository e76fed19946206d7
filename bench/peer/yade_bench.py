# -*- coding: utf-8 -*-
"""YADE peer of `grainlab bench triaxial-iso`: the same packing, law and servo, timed.

Usage:
    yade -n -j THREADS -x bench/peer/yade_bench.py PACKING --steps S [--dt DT] [--warmup 200]

PACKING is the scene's cached grainlab packing file (~/.cache/grainlab/triaxial-iso-N.txt: a '#'
line, the six wall planes xlo xhi ylo yhi zlo zhi, then radius x y z per sphere). --dt is grainlab's
time step for the same sample (printed by `grainlab bench --json`); without it 0.5 PWaveTimeStep().

The scene of the grainlab bench: Ec = 30 GPa, ks/kn = 0.3, mu = 30 deg, contact moments with
beta = 0.15 and eta = 1 (YADE's CohFrictMat, alphaKr = alphaKtw = beta, etaRoll = etaTwist = eta,
momentRotationLaw, always_use_moment_law, useIncrementalForm), rho = 2600 kg/m3, Cundall damping
0.3, no gravity, six frictionless rigid walls (Box bodies) all servo-controlled at 100 kPa by
TriaxialStressController. YADE caps the bending moment by eta * min(R1, R2) * Fn where grainlab
uses eta * (R1 + R2) / 2 * Fn: below the cap both are the same elastic law, and in an isotropically
compressed sample almost no contact reaches it, so the work per step is the same.

Prints one JSON line: scene, n_particles, n_contacts, steps, seconds, particle_steps_per_s, threads.
"""

import argparse
import json
import math
import sys
import time

from yade import O, utils
from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, CohFrictMat, ForceResetter,
                          Ig2_Box_Sphere_ScGeom6D, Ig2_Sphere_Sphere_ScGeom6D,
                          InsertionSortCollider, InteractionLoop,
                          Ip2_CohFrictMat_CohFrictMat_CohFrictPhys,
                          Law2_ScGeom6D_CohFrictPhys_CohesionMoment, NewtonIntegrator,
                          TriaxialStressController)

parser = argparse.ArgumentParser(prog='yade -n -x yade_bench.py')
parser.add_argument('packing')
parser.add_argument('--steps', type=int, default=2000)
parser.add_argument('--warmup', type=int, default=200)
parser.add_argument('--dt', type=float, default=None)
parser.add_argument('--pressure', type=float, default=100e3)
args = parser.parse_args(sys.argv[1:])

YOUNG, KS_KN, FRICTION_DEG, BETA, ETA, DENSITY, DAMPING = 30e9, 0.3, 30.0, 0.15, 1.0, 2600.0, 0.3

with open(args.packing) as f:
    rows = [l for l in f if l.strip() and not l.lstrip().startswith('#')]
planes = [float(v) for v in rows[0].split()]
spheres = [tuple(float(v) for v in l.split()[:4]) for l in rows[1:]]

grains = O.materials.append(CohFrictMat(
    young=YOUNG, poisson=KS_KN, density=DENSITY, frictionAngle=math.radians(FRICTION_DEG),
    isCohesive=False, normalCohesion=-1, shearCohesion=-1, momentRotationLaw=True,
    alphaKr=BETA, alphaKtw=BETA, etaRoll=ETA, etaTwist=ETA))
walls = O.materials.append(CohFrictMat(
    young=1e6 * YOUNG, poisson=KS_KN, density=0.0, frictionAngle=0.0, isCohesive=False,
    momentRotationLaw=False, alphaKr=0.0, alphaKtw=0.0, etaRoll=0.0, etaTwist=0.0))

# Six Box walls whose inner faces lie on the planes; ids 0..5 = xlo, xhi, ylo, yhi, zlo, zhi.
L = [planes[2 * a + 1] - planes[2 * a] for a in range(3)]
mid = [0.5 * (planes[2 * a] + planes[2 * a + 1]) for a in range(3)]
thick = 0.1 * min(L)
for axis in range(3):
    for side in (0, 1):
        center = list(mid)
        center[axis] = planes[2 * axis + side] + (thick / 2 if side else -thick / 2)
        ext = [1.5 * max(L)] * 3
        ext[axis] = thick / 2
        O.bodies.append(utils.box(center=center, extents=ext, fixed=True, wire=True, material=walls))
for r, x, y, z in spheres:
    O.bodies.append(utils.sphere((x, y, z), r, material=grains))

O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
    TriaxialStressController(internalCompaction=False, thickness=thick, wall_left_id=0, wall_right_id=1,
                             wall_bottom_id=2, wall_top_id=3, wall_back_id=4, wall_front_id=5,
                             stressMask=7, goal1=-args.pressure, goal2=-args.pressure,
                             goal3=-args.pressure, max_vel=1.0),
    NewtonIntegrator(damping=DAMPING, gravity=(0, 0, 0)),
]
O.dt = args.dt if args.dt else 0.5 * utils.PWaveTimeStep()

O.run(args.warmup, True)
t0 = time.time()
O.run(args.steps, True)
seconds = time.time() - t0
contacts = sum(1 for i in O.interactions  # sphere-sphere, as grainlab counts them
               if i.isReal and i.id1 >= 6 and i.id2 >= 6 and i.phys.normalForce.norm() > 0)
print(json.dumps({"scene": "triaxial-iso", "program": "yade", "n_particles": len(spheres),
                  "n_contacts": contacts, "steps": args.steps, "seconds": seconds,
                  "particle_steps_per_s": args.steps * len(spheres) / seconds,
                  "threads": O.numThreads, "dt": O.dt}))
sys.stdout.flush()
import os  # noqa: E402
os._exit(0)  # YADE's interpreter would otherwise stay open after -x on some builds
