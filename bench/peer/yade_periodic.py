# -*- coding: utf-8 -*-
"""Independent peer run of grainlab's drained triaxial test in a periodic cell, in YADE (tested
with 2023.02a).

Usage:
    yade -n -x bench/peer/yade_periodic.py PACKING OUT.csv [--strain 0.08] [--rate 1.0]
                                           [--pressure 100e3] [--relax-steps 3000]

PACKING: a grainlab packing file (format 2) of a periodic cell: the cell matrix H and the spheres,
assumed in equilibrium at the pressure. Contact law: yade_scene.py (CohFrictMat, incremental
moments; bending and twisting each capped at eta min(R1, R2) |Fn|, which grainlab reproduces with
contact.moment_limit = "yade").

Loading: PeriTriaxController. First --relax-steps steps with all three normal stresses servoed at
the pressure, then the axial (z) strain imposed at --rate (YADE's strain rate of the cell, a true
strain rate) while x and y stay stress-controlled at the pressure, to --strain of engineering
axial strain.

CSV columns (compression / contraction positive, stresses in Pa):
    step, eps1, eps_v, sigma1, sigma3, phi_deg, Z, unbalanced
    eps1 = (H0_zz - H_zz)/H0_zz and eps_v = (V0 - V)/V0 from the cell; sigma from utils.getStress()
    (Love–Weber over the contacts; sigma3 the mean of x and y); phi = asin((s1 - s3)/(s1 + s3));
    Z = 2 * (contacts with Fn > 0) / n_spheres.
"""
import argparse
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: the script's folder
from yade import O, utils  # noqa: E402
from yade.wrapper import PeriTriaxController  # noqa: E402
from yade.minieigenHP import Matrix3, Vector3  # noqa: E402 (Debian yade 2023: no separate minieigen)
import yade_scene  # noqa: E402

parser = argparse.ArgumentParser(prog='yade -n -x yade_periodic.py')
parser.add_argument('packing')
parser.add_argument('out')
parser.add_argument('--strain', type=float, default=0.08, help='final engineering axial strain [-]')
parser.add_argument('--rate', type=float, default=1.0, help='axial strain rate [1/s]')
parser.add_argument('--pressure', type=float, default=100e3, help='confining pressure [Pa]')
parser.add_argument('--relax-steps', type=int, default=3000)
parser.add_argument('--record-every', type=float, default=5e-4, help='axial strain between rows [-]')
parser.add_argument('--dt-factor', type=float, default=0.5, help='dt = factor * PWaveTimeStep()')
args = parser.parse_args(sys.argv[1:])

spheres = yade_scene.build_periodic(args.packing)
nSpheres = len(spheres)

ctrl = PeriTriaxController(goal=Vector3(-args.pressure, -args.pressure, -args.pressure), stressMask=7,
                           maxStrainRate=Vector3(1.0, 1.0, 1.0), maxUnbalanced=1e-3, label='ctrl')
O.engines = yade_scene.periodic_engines(ctrl)
O.dt = args.dt_factor * utils.PWaveTimeStep()


def stress():
    s = utils.getStress()
    return -s[2, 2], -0.5 * (s[0, 0] + s[1, 1])


def coordination():
    n = sum(1 for i in O.interactions if i.isReal and i.phys.normalForce.norm() > 0)
    return 2.0 * n / nSpheres


t0 = time.time()
O.run(args.relax_steps, True)
s1, s3 = stress()
print('relaxation: %d steps, dt = %.4e s, sigma_zz %.2f kPa, sigma_lat %.2f kPa, unbalanced %.3e'
      % (args.relax_steps, O.dt, s1 / 1e3, s3 / 1e3, utils.unbalancedForce()))

# Shear: z strain-controlled at the rate (the goal is a log strain beyond the final one), x and y
# stress-controlled. The strain the controller reports counts from here.
O.cell.trsf = Matrix3.Identity
ctrl.stressMask = 3
ctrl.goal = Vector3(-args.pressure, -args.pressure, -1.5 * args.strain)
ctrl.maxStrainRate = Vector3(1.0, 1.0, args.rate)
H0 = O.cell.hSize[2, 2]
V0 = O.cell.volume
rows, nextRecord, step0 = [], 0.0, O.iter
tShear = time.time()
while True:
    O.run(100, True)
    eps1 = (H0 - O.cell.hSize[2, 2]) / H0
    if eps1 >= nextRecord or eps1 >= args.strain:
        s1, s3 = stress()
        phi = math.degrees(math.asin((s1 - s3) / (s1 + s3)))
        rows.append((O.iter - step0, eps1, (V0 - O.cell.volume) / V0, s1, s3, phi, coordination(),
                     utils.unbalancedForce()))
        nextRecord += args.record_every
    if eps1 >= args.strain:
        break
seconds = time.time() - tShear
with open(args.out, 'w') as f:
    f.write('step,eps1,eps_v,sigma1,sigma3,phi_deg,Z,unbalanced\n')
    for r in rows:
        f.write('%d,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g\n' % r)
print('shear: %d steps in %.1f s (%.3g particle-steps/s), %d rows in %s'
      % (O.iter - step0, seconds, nSpheres * (O.iter - step0) / seconds, len(rows), args.out))
# yade -x exits when the script ends (Debian's 2023.02a Omega has no exit()).
