# -*- coding: utf-8 -*-
"""The YADE scene shared by the peer scripts (yade_triaxial.py, yade_bench.py, yade_periodic.py): the [W] parameters,
a grainlab packing file read back (format 2 or 1, by packing_file.py), the two CohFrictMat
materials, six Box walls on the packing's planes (ids 0..5 = xlo, xhi, ylo, yhi, zlo, zhi,
TriaxialStressController's numbering), the spheres, and the engine list. Imported by those scripts under `yade -x`, which puts their folder
on sys.path first. The law YADE applies is documented in yade_triaxial.py.
"""
import math

from packing_file import read_packing  # noqa: F401 (the scripts call yade_scene.read_packing)
from yade import O, utils
from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, CohFrictMat, ForceResetter,
                          Ig2_Box_Sphere_ScGeom6D, Ig2_Sphere_Sphere_ScGeom6D,
                          InsertionSortCollider, InteractionLoop,
                          Ip2_CohFrictMat_CohFrictMat_CohFrictPhys,
                          Law2_ScGeom6D_CohFrictPhys_CohesionMoment, NewtonIntegrator)

YOUNG = 30e9            # E [Pa]
KS_KN = 0.3             # ks/kn (YADE 'poisson')
FRICTION_DEG = 30.0     # interparticle friction angle
BETA = 0.15             # alphaKr = alphaKtw
ETA = 1.0               # etaRoll = etaTwist
DENSITY = 2600.0        # [kg/m3]
DAMPING = 0.3           # Cundall non-viscous damping


def sphere_material(moments=True):
    """The spheres' CohFrictMat with the [W] parameters; returns its id."""
    return O.materials.append(CohFrictMat(
        young=YOUNG, poisson=KS_KN, density=DENSITY, frictionAngle=math.radians(FRICTION_DEG),
        isCohesive=False, normalCohesion=-1, shearCohesion=-1, momentRotationLaw=moments,
        alphaKr=BETA if moments else 0.0, alphaKtw=BETA if moments else 0.0,
        etaRoll=ETA if moments else 0.0, etaTwist=ETA if moments else 0.0, label='spheres'))


def build(planes, spheres, moments=True, wall_young=None):
    """Materials, the six walls and the spheres; returns the walls' common thickness."""
    sphere_mat = sphere_material(moments)
    wall_mat = O.materials.append(CohFrictMat(
        young=wall_young if wall_young is not None else 1e6 * YOUNG, poisson=KS_KN, density=0.0,
        frictionAngle=0.0, isCohesive=False, momentRotationLaw=False, alphaKr=0.0, alphaKtw=0.0,
        etaRoll=0.0, etaTwist=0.0, label='walls'))
    L = [planes[2 * a + 1] - planes[2 * a] for a in range(3)]
    mid = [0.5 * (planes[2 * a] + planes[2 * a + 1]) for a in range(3)]
    thick = 0.1 * min(L)
    for axis in range(3):
        for side in (0, 1):                              # 0: lower plane, 1: upper plane
            center = list(mid)
            center[axis] = planes[2 * axis + side] + (thick / 2 if side else -thick / 2)
            ext = [1.5 * max(L)] * 3                     # wide enough for lateral bulging
            ext[axis] = thick / 2
            O.bodies.append(utils.box(center=center, extents=ext, fixed=True, wire=True,
                                      material=wall_mat))
    for r, x, y, z in spheres:
        O.bodies.append(utils.sphere((x, y, z), r, material=sphere_mat))
    return thick


def engines(controller, extra=(), law_label=None):
    """The engine list: collider, the CohFrictMat law with incremental moments, the wall
    controller, any extra engines, then Newton with the [W] damping and no gravity."""
    law = Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)
    if law_label:
        law.label = law_label
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()], [law]),
        controller,
        *extra,
        NewtonIntegrator(damping=DAMPING, gravity=(0, 0, 0)),
    ]


def build_periodic(path):
    """A periodic cell from a grainlab packing of a cell (O.cell.hSize from the file) and its spheres
    with the [W] material; returns the spheres [(r, x, y, z)]."""
    from yade.minieigenHP import Matrix3  # Debian yade 2023: no separate minieigen
    import packing_file
    cell_rows, spheres = packing_file.read_periodic_packing(path)
    O.periodic = True
    O.cell.hSize = Matrix3(*[v for row in cell_rows for v in row])
    material = sphere_material(moments=True)
    for r, x, y, z in spheres:
        O.bodies.append(utils.sphere((x, y, z), r, material=material))
    return spheres


def periodic_engines(controller):
    """The engine list of a periodic cell: collider, the CohFrictMat law with incremental moments,
    the cell's controller (PeriTriaxController), then Newton with the [W] damping and no gravity."""
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D()], [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
        controller,
        NewtonIntegrator(damping=DAMPING, gravity=(0, 0, 0)),
    ]

