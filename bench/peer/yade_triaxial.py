# -*- coding: utf-8 -*-
"""Independent peer run of grainlab's drained triaxial test in YADE (tested with 2023.02a).

Usage:
    yade -n -x bench/peer/yade_triaxial.py PACKING OUT.csv [--no-moments] [--strain 0.02]
                                           [--rate 1.0] [--relax-steps 2000] [--wall-young 3e16]
                                           [--servo-integral 0.01]

PACKING: a grainlab packing file (README "Packing files": format 2, or format 1 with a '#' comment,
the six wall planes xlo xhi ylo yhi zlo zhi [m], then radius x y z [m] per sphere), read by
packing_file.py; the packing is assumed to be in equilibrium.

Contact law: YADE's CohFrictMat / CohFrictPhys with Law2_ScGeom6D_CohFrictPhys_CohesionMoment
(incremental moments, no cohesion). What YADE 2023.02a computes for a contact between spheres of
radii R1, R2 (Ip2_CohFrictMat_CohFrictMat_CohFrictPhys, equal materials):
    kn  = 2 E R1 R2 / (R1 + R2)
    ks  = poisson * kn                      (YADE's 'poisson' is the ks/kn ratio here)
    kr  = alphaKr  * ks * R1 R2             (bending/rolling moment, M_b += -kr * dtheta_bend)
    ktw = alphaKtw * ks * R1 R2             (twisting moment,        M_t += -ktw * dtheta_twist)
    |Fs|  <= tan(frictionAngle) * Fn
    |M_b| <= min(etaRoll  R1, etaRoll  R2) * |Fn|   (bending and twisting are capped separately)
    |M_t| <= min(etaTwist R1, etaTwist R2) * |Fn|
Walls are Box bodies (Ig2_Box_Sphere_ScGeom6D sets radius1 = radius2 = R_sphere), so a wall contact
gets kn = 2 E R E_w R / (E R + E_w R); with E_w >> E (default --wall-young 1e6 E) this is the
rigid-wall value kn = 2 E R. Walls are frictionless (tan(0) = 0 -> no shear force) and carry no
moment (momentRotationLaw=False on the wall material).

Loading: TriaxialStressController keeps the four lateral walls (x, y) at sigma3 = 100 kPa; the two
z platens move at constant, opposite speeds v = rate * H0 / 2 (engineering strain rate on the
height H0 at the start of shear). The controller is a proportional servo, so a wall moving at a
steady speed lags by a steady stress error (~3 % at 1 /s); an outer integral loop on its goals
(--servo-integral, per step) removes that offset. Before shearing, all six walls are
servo-controlled at 100 kPa for --relax-steps steps (no integral loop, walls nearly at rest).
Rate sensitivity: at 1 /s the frictional no-moment case is not fully quasi-static (phi about 3 deg
higher than at 0.25 /s on packing400u); with moments the difference is below about 1 deg.

CSV columns (compression / contraction positive, stresses in Pa):
    step, eps1, eps_v, sigma1, sigma3, phi_deg, Z, unbalanced
    eps1 = (H0 - H)/H0 from the platen planes, eps_v = (V0 - V)/V0 from the six wall planes,
    sigma1 = mean platen force / (Lx Ly), sigma3 = mean of the four lateral wall stresses,
    phi_deg = asin((s1 - s3)/(s1 + s3)), Z = 2 * (sphere-sphere contacts with Fn > 0) / n_spheres,
    unbalanced = utils.unbalancedForce().
"""

import argparse
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: the script's folder
import yade  # noqa: E402
from yade import O, utils  # noqa: E402
from yade.wrapper import PyRunner, TriaxialStressController  # noqa: E402
import yade_scene  # noqa: E402
from yade_scene import BETA, YOUNG  # noqa: E402

# ---------------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------------
parser = argparse.ArgumentParser(prog='yade -n -x yade_triaxial.py',
                                 description='YADE peer run of the grainlab triaxial test')
parser.add_argument('packing', help='grainlab packing file (format 2 or 1)')
parser.add_argument('out', help='output CSV path')
parser.add_argument('--no-moments', action='store_true',
                    help='disable contact moments (momentRotationLaw=False, alphaKr=etaRoll=0)')
parser.add_argument('--strain', type=float, default=0.02, help='final axial strain [-]')
parser.add_argument('--rate', type=float, default=1.0, help='axial strain rate [1/s]')
parser.add_argument('--pressure', type=float, default=100e3, help='confining pressure [Pa]')
parser.add_argument('--relax-steps', type=int, default=2000,
                    help='steps of isotropic servo relaxation before shearing')
parser.add_argument('--record-every', type=float, default=5e-4,
                    help='axial strain between CSV rows [-]')
parser.add_argument('--dt-factor', type=float, default=0.5, help='dt = factor * PWaveTimeStep()')
parser.add_argument('--servo-integral', type=float, default=0.01,
                    help='gain (per step) of the integral correction of the lateral stress goals; '
                         '0 = plain TriaxialStressController')
parser.add_argument('--wall-young', type=float, default=None,
                    help='Young modulus of the wall material [Pa] (default 1e6 * sphere young, '
                         'i.e. rigid-wall kn = 2 E R; use 30e9 for YADE\'s equal-material kn = E R)')
args = parser.parse_args(sys.argv[1:])

# ---------------------------------------------------------------------------------------------
# Scene (yade_scene.py): the [W] parameters, the packing, materials, six Box walls whose inner faces
# lie on the given planes (ids 0..5 = xlo, xhi, ylo, yhi, zlo, zhi, TriaxialStressController's
# default numbering), then the spheres.
# ---------------------------------------------------------------------------------------------
moments = not args.no_moments
planes, spheresIn = yade_scene.read_packing(args.packing)
nSpheres = len(spheresIn)
thick = yade_scene.build(planes, spheresIn, moments=moments, wall_young=args.wall_young)
WALL_IDS = list(range(6))


def plane(i):
    """Position of the inner face of wall i (0..5)."""
    axis, side = divmod(i, 2)
    c = O.bodies[i].state.pos[axis]
    return c + thick / 2 if side == 0 else c - thick / 2


def dims():
    return [plane(2 * a + 1) - plane(2 * a) for a in range(3)]


def wallStresses():
    """Normal stress on each of the six walls, compression positive [Pa]."""
    lx, ly, lz = dims()
    area = (ly * lz, lx * lz, lx * ly)
    s = []
    for i in WALL_IDS:
        axis, side = divmod(i, 2)
        fa = O.forces.f(i)[axis]          # force of the spheres on the wall
        s.append((-fa if side == 0 else fa) / area[axis])
    return s


def contactCoordination():
    """Z = 2 * (sphere-sphere interactions with a compressive normal force) / n_spheres."""
    n = 0
    for i in O.interactions:
        if i.id1 >= 6 and i.id2 >= 6 and i.isReal and i.phys.normalForce.norm() > 0:
            n += 1
    return 2.0 * n / nSpheres


# ---------------------------------------------------------------------------------------------
# Engines
# ---------------------------------------------------------------------------------------------
triax = TriaxialStressController(
    internalCompaction=False, thickness=thick,
    wall_left_id=0, wall_right_id=1, wall_bottom_id=2, wall_top_id=3, wall_back_id=4,
    wall_front_id=5,
    stressMask=7, goal1=-args.pressure, goal2=-args.pressure, goal3=-args.pressure,  # tension > 0
    max_vel=1.0, label='triax')

shearRunner = PyRunner(iterPeriod=1, command='shearStep()', dead=True, label='shearRunner')

O.engines = yade_scene.engines(triax, extra=[shearRunner], law_label='law')
O.dt = args.dt_factor * utils.PWaveTimeStep()

# ---------------------------------------------------------------------------------------------
# Phase 1: isotropic relaxation, all six walls servo-controlled at the confining pressure
# ---------------------------------------------------------------------------------------------
tStart = time.time()
O.run(args.relax_steps, True)
tRelax = time.time() - tStart
sRelax = wallStresses()
print('relaxation: %d steps in %.2f s, dt = %.4e s, wall stresses [kPa] = %s, unbalanced = %.3e'
      % (args.relax_steps, tRelax, O.dt, ' '.join('%.2f' % (s / 1e3) for s in sRelax),
         utils.unbalancedForce()))

# A sample interaction, to check the stiffnesses YADE assigned.
for i in O.interactions:
    if i.id1 >= 6 and i.id2 >= 6 and i.isReal:
        r1, r2 = O.bodies[i.id1].shape.radius, O.bodies[i.id2].shape.radius
        p = i.phys
        print('sample contact: R1=%.4e R2=%.4e kn=%.5e (2ER1R2/(R1+R2)=%.5e) ks/kn=%.4f '
              'kr=%.5e (beta ks R1R2=%.5e) ktw=%.5e maxRollPl=%.4e maxTwistPl=%.4e (min R=%.4e)'
              % (r1, r2, p.kn, 2 * YOUNG * r1 * r2 / (r1 + r2), p.ks / p.kn, p.kr,
                 BETA * p.ks * r1 * r2, p.ktw, p.maxRollPl, p.maxTwistPl, min(r1, r2)))
        break
for i in O.interactions:
    if min(i.id1, i.id2) < 6 and i.isReal:
        r = O.bodies[max(i.id1, i.id2)].shape.radius
        print('sample wall contact: R=%.4e kn=%.5e (2ER=%.5e) tanPhi=%g momentRotationLaw=%s'
              % (r, i.phys.kn, 2 * YOUNG * r, i.phys.tangensOfFrictionAngle,
                 i.phys.momentRotationLaw))
        break

# ---------------------------------------------------------------------------------------------
# Phase 2: shear. Lateral walls keep sigma3 (stressMask=3: axes x and y stress-controlled);
# the platens are released from the controller (it then zeroes their velocity every step) and
# shearStep(), which runs after it, imposes the constant platen speed.
# ---------------------------------------------------------------------------------------------
H0 = dims()[2]
V0 = dims()[0] * dims()[1] * dims()[2]
vPlaten = 0.5 * args.rate * H0
triax.stressMask = 3
triax.wall_back_activated = False
triax.wall_front_activated = False

rows = []
state = {'integral': [0.0, 0.0], 'next': 0.0, 'maxDevWall': 0.0, 'nWallOver2': 0, 'maxDev3': 0.0,
         'sumDev3': 0.0, 'nDev3': 0}
step0 = O.iter


def record(eps1):
    lx, ly, lz = dims()
    s = wallStresses()
    s1 = 0.5 * (s[4] + s[5])
    s3 = 0.25 * (s[0] + s[1] + s[2] + s[3])
    phi = math.degrees(math.asin((s1 - s3) / (s1 + s3)))
    epsV = (V0 - lx * ly * lz) / V0
    rows.append((O.iter - step0, eps1, epsV, s1, s3, phi, contactCoordination(),
                 utils.unbalancedForce()))
    print('eps1=%.5f  eps_v=%+.5f  s1=%.1f kPa  s3=%.2f kPa  phi=%.2f deg  Z=%.3f  unb=%.3e'
          % (rows[-1][1:3] + (s1 / 1e3, s3 / 1e3) + rows[-1][5:]))


def shearStep():
    O.bodies[4].state.vel = (0, 0, vPlaten)
    O.bodies[5].state.vel = (0, 0, -vPlaten)
    eps1 = (H0 - dims()[2]) / H0
    s = wallStresses()
    # TriaxialStressController is a proportional displacement servo: a wall moving at a steady
    # speed lags behind its goal by a steady stress error (~3 % here). An outer integral loop on
    # the goals (per axis) removes that offset; it acts on the goal, the controller is unchanged.
    if args.servo_integral > 0:
        for axis in (0, 1):
            err = 0.5 * (s[2 * axis] + s[2 * axis + 1]) - args.pressure
            state['integral'][axis] += args.servo_integral * err
            goal = -(args.pressure - state['integral'][axis])
            if axis == 0:
                triax.goal1 = goal
            else:
                triax.goal2 = goal
    # servo quality on the lateral walls (per wall, and for the recorded mean sigma3)
    devWall = max(abs(s[k] - args.pressure) for k in range(4)) / args.pressure
    dev3 = abs(0.25 * sum(s[:4]) - args.pressure) / args.pressure
    state['maxDevWall'] = max(state['maxDevWall'], devWall)
    state['nWallOver2'] += devWall > 0.02
    state['maxDev3'] = max(state['maxDev3'], dev3)
    state['sumDev3'] += dev3
    state['nDev3'] += 1
    if eps1 >= state['next'] - 1e-12:
        record(eps1)
        state['next'] += args.record_every
    if eps1 >= args.strain - 1e-12:
        O.pause()


shearRunner.dead = False
tShear0 = time.time()
O.run()
O.wait()
tShear = time.time() - tShear0
nShear = O.iter - step0

with open(args.out, 'w') as f:
    f.write('step,eps1,eps_v,sigma1,sigma3,phi_deg,Z,unbalanced\n')
    for r in rows:
        f.write('%d,%.8g,%.8g,%.8g,%.8g,%.8g,%.6g,%.6g\n' % r)

print('YADE %s, moments=%s, n=%d spheres, dt=%.4e s, platen speed=%.4e m/s'
      % (yade.config.version if hasattr(yade, 'config') else '?', moments, nSpheres, O.dt,
         vPlaten))
print('shear: %d steps in %.1f s (%.0f steps/s); relaxation %d steps in %.1f s'
      % (nShear, tShear, nShear / max(tShear, 1e-9), args.relax_steps, tRelax))
nDev = max(state['nDev3'], 1)
print('lateral servo (every step): mean sigma3 off by %.3f %% on average, %.2f %% at worst; single '
      'walls off by %.2f %% at worst, by more than 2 %% in %.2f %% of the steps'
      % (100 * state['sumDev3'] / nDev, 100 * state['maxDev3'], 100 * state['maxDevWall'],
         100.0 * state['nWallOver2'] / nDev))
print('wrote %s (%d rows)' % (args.out, len(rows)))
