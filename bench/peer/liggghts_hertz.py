#!/usr/bin/env python3
"""Hertz–Mindlin in grainlab and in LIGGGHTS 3.8 (`model hertz tangential history`) on the same packing
under the same small isotropic compression (issue 27 §1: the same model must give the same answer).

Usage:
    /usr/bin/python3 bench/peer/liggghts_hertz.py [--particles 1000] [--strain 1e-4] [--friction-deg 0 30]
        [--restitution 0.3] [--out runs/peer-hertz] [--json FILE]

1. grainlab prepares a sample of quartz-like spheres (G 29 GPa, nu 0.2, 2-4 mm, density 2650) at
   100 kPa between six walls with Hertz–Mindlin, frictionless (`grainlab run`, its packing.txt).
2. For each friction angle, grainlab (the Python module) loads that packing, brings it to rest at
   100 kPa with the angle's friction, and this state (positions, radii, wall planes) is written for
   LIGGGHTS. Both codes then start from it: (a) the stress on the fixed walls as it stands (the same
   configuration, so the same forces if the laws agree: a check of the normal law, E*, R*, the walls;
   LIGGGHTS sums its meshes' forces in a step, so its value is after one step at rest);
   (b) the six walls move inwards at the same constant speeds for the same number of steps (axial
   strain `--strain` on each axis), then stand still while the sample comes to rest; the mean wall
   stress at rest is compared.
   Both run the same dashpots (coefficient of restitution, Tsuji's damping ratio, normal only:
   LIGGGHTS `tangential_damping off`), no local damping in grainlab, the same time step, no gravity.
   The walls are LIGGGHTS meshes of the grains' elastic material (`fix mesh/surface/stress`,
   `move/mesh linear`), as grainlab's walls are (R* = r, the same E*), and smooth, as grainlab's are.
3. Prints a table and, with --json, writes every number.

Known differences of the laws, not of the model: LIGGGHTS keeps the tangential spring's force as it
is when the overlap shrinks (grainlab scales it with the stiffness, Walton's rule, docs/physics.md
§4.6), and LIGGGHTS' integrator is velocity Verlet where grainlab's is leapfrog. Frictionless, the
tangential law does not act, so (b) then compares the normal law and the equilibrium alone.
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
from packing_file import read_packing  # noqa: E402

G, NU, RHO = 29e9, 0.2, 2650.0
E = 2.0 * G * (1.0 + NU)
PRESSURE = 1e5


def grainlab_paths(build):
    exe = os.path.join(build, "grainlab")
    pydir = os.path.join(build, "python")
    if not os.path.exists(exe):
        sys.exit(f"no grainlab executable at {exe} (build first, or give --build)")
    return exe, pydir


def common_sets(friction, restitution):
    return [f"contact.model=\"hertz-mindlin\"", f"contact.shear_modulus={G!r}", f"contact.poisson={NU!r}",
            f"contact.friction_deg={friction!r}", f"contact.restitution={restitution!r}", f"sample.density={RHO!r}",
            'sample.grading={type="uniform", d_min=2e-3, d_max=4e-3}', 'test.type="isotropic"',
            f"test.confining_pressure={PRESSURE!r}", "output.plots=false", "output.vtk_every_strain=0"]


def prepare(exe, out, n, seed, restitution):
    args = [exe, "run", "preset:quick-triaxial", "--out", out, "--quiet", "--threads", "1",
            "--set", f"sample.n_particles={n}", "--set", f"sample.seed={seed}", "--set", "sample.prep_friction_deg=0",
            "--set", "sample.e0_tolerance=1.0"]
    for s in common_sets(0.0, restitution):
        args += ["--set", s]
    subprocess.run(args, check=True)
    return os.path.join(out, "packing.txt")


def grainlab_case(pydir, packing, friction, restitution, strain, rest_steps_max, unbalanced_tol):
    sys.path.insert(0, pydir)
    import grainlab  # noqa: E402
    sets = common_sets(friction, restitution) + [f"sample.packing=\"{packing}\"", "solver.damping=0.0"]
    cfg = grainlab.load_config("preset:quick-triaxial", sets)
    sim = grainlab.Simulation(cfg, threads=1)
    # Rest at p with this friction (the packing's own equilibrium plus the friction's re-equilibration).
    start = {"positions": sim.positions.copy(), "radii": sim.radii.copy(), "planes": list(sim.wall_positions),
             "stress": list(sim.boundary_stress), "dt": sim.dt, "masses": sim.masses.copy()}
    # Compression: each axis at a constant rate for `steps` steps, then walls fixed.
    steps = 2000
    rate = strain / (steps * sim.dt)
    for axis in range(3):
        sim.set_strain_rate(axis, rate)
    sim.step(steps)
    moved = list(sim.wall_positions)
    for axis in range(3):
        sim.set_strain_rate(axis, 0.0)
    done = 0
    while done < rest_steps_max:
        sim.step(1000)
        done += 1000
        if sim.unbalanced < unbalanced_tol:
            break
    return start, moved, steps, {"stress": list(sim.boundary_stress), "unbalanced": sim.unbalanced,
                                 "rest_steps": done, "coordination": sim.coordination}


def stl_square(path, axis, position, lo, hi):
    """Two triangles covering the plane x[axis] = position over [lo, hi] of the other two axes."""
    u, v = [a for a in range(3) if a != axis]

    def point(a, b):
        p = [0.0, 0.0, 0.0]
        p[axis], p[u], p[v] = position, a, b
        return p
    corners = [point(lo[u], lo[v]), point(hi[u], lo[v]), point(hi[u], hi[v]), point(lo[u], hi[v])]
    normal = [0.0, 0.0, 0.0]
    normal[axis] = 1.0
    with open(path, "w") as f:
        f.write("solid wall\n")
        for tri in ((0, 1, 2), (0, 2, 3)):
            f.write(f"  facet normal {normal[0]} {normal[1]} {normal[2]}\n    outer loop\n")
            for k in tri:
                f.write("      vertex {!r} {!r} {!r}\n".format(*corners[k]))
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid wall\n")


def liggghts_case(exe, folder, start, moved, steps, friction, restitution, rest_steps_max):
    planes = start["planes"]
    lo = [planes[0], planes[2], planes[4]]
    hi = [planes[1], planes[3], planes[5]]
    size = max(h - l for l, h in zip(lo, hi))
    pad = 0.2 * size
    big_lo = [l - pad for l in lo]
    big_hi = [h + pad for h in hi]
    with open(os.path.join(folder, "spheres.data"), "w") as f:
        f.write("grainlab packing for LIGGGHTS\n\n")
        f.write(f"{len(start['radii'])} atoms\n2 atom types\n\n")
        for a, name in enumerate("xyz"):
            f.write(f"{big_lo[a]!r} {big_hi[a]!r} {name}lo {name}hi\n")
        f.write("\nAtoms\n\n")
        for i, (r, x) in enumerate(zip(start["radii"], start["positions"]), start=1):
            f.write(f"{i} 1 {2.0 * float(r)!r} {RHO!r} {float(x[0])!r} {float(x[1])!r} {float(x[2])!r}\n")
    dt = start["dt"]
    law = "model hertz tangential history tangential_damping off"
    lines = ["atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "units si", "hard_particles yes", "read_data spheres.data",
             "neighbor 0.0004 bin", "neigh_modify delay 0",
             # Material 1: the grains; 2: the walls, of the same elastic material but smooth, as
             # grainlab's walls are by default (test.wall_friction_deg = 0).
             f"fix ym all property/global youngsModulus peratomtype {E!r} {E!r}",
             f"fix pr all property/global poissonsRatio peratomtype {NU!r} {NU!r}",
             "fix cr all property/global coefficientRestitution peratomtypepair 2 " + f"{restitution!r} " * 4,
             f"fix cf all property/global coefficientFriction peratomtypepair 2 {math.tan(math.radians(friction))!r} 0 0 0",
             f"pair_style gran {law}", "pair_coeff * *", f"timestep {dt!r}"]
    walls = []
    for a in range(3):
        for side in range(2):
            name = f"w{a}{side}"
            stl_square(os.path.join(folder, f"{name}.stl"), a, planes[2 * a + side], big_lo, big_hi)
            lines.append(f"fix {name} all mesh/surface/stress file {name}.stl type 2")
            walls.append(name)
    # (a fix's model keywords follow its wall arguments)
    lines.append(f"fix walls all wall/gran model hertz tangential history mesh n_meshes 6 meshes {' '.join(walls)} "
                 "tangential_damping off")
    lines += ["fix integr all nve/sphere",
              # |force| on each wall along its axis, summed to the mean boundary stress in Python
              "variable fx0 equal f_w00[1]", "variable fx1 equal f_w01[1]", "variable fy0 equal f_w10[2]",
              "variable fy1 equal f_w11[2]", "variable fz0 equal f_w20[3]", "variable fz1 equal f_w21[3]",
              "compute ke all ke",
              "thermo_style custom step v_fx0 v_fx1 v_fy0 v_fy1 v_fz0 v_fz1 c_ke", "thermo_modify format float %.12g",
              # (the meshes' force totals are first summed by a step: one step at rest)
              "thermo 1000", "run 1"]
    # The walls move inwards at grainlab's speeds for the same number of steps, then stop.
    for a in range(3):
        for side in range(2):
            v = (moved[2 * a + side] - planes[2 * a + side]) / (steps * dt)
            vel = [0.0, 0.0, 0.0]
            vel[a] = v
            lines.append(f"fix mv{a}{side} all move/mesh mesh w{a}{side} linear {vel[0]!r} {vel[1]!r} {vel[2]!r}")
    lines.append(f"run {steps}")
    lines += [f"unfix mv{a}{side}" for a in range(3) for side in range(2)]
    lines.append(f"run {rest_steps_max}")
    with open(os.path.join(folder, "in.hertz"), "w") as f:
        f.write("\n".join(lines) + "\n")
    # (-screen none makes LIGGGHTS 3.8 crash while it reads a mesh: the screen goes to a file)
    proc = subprocess.run([exe, "-in", "in.hertz", "-log", "log.hertz", "-echo", "none", "-screen", "screen.txt"],
                          cwd=folder, capture_output=True, text=True, timeout=7200)
    log = open(os.path.join(folder, "log.hertz"), errors="replace").read() if os.path.exists(os.path.join(folder, "log.hertz")) else ""
    if proc.returncode != 0:
        sys.exit(f"liggghts failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}{log[-3000:]}")
    num = r"[-+0-9.eE]+"
    rows = [tuple(float(v) for v in m) for m in
            re.findall(rf"^\s*(\d+)\s+({num})\s+({num})\s+({num})\s+({num})\s+({num})\s+({num})\s+({num})\s*$",
                       log, flags=re.M)]

    def stress(row, box_lo, box_hi):
        length = [h - l for l, h in zip(box_lo, box_hi)]
        area = [length[1] * length[2], length[0] * length[2], length[0] * length[1]]
        f = row[1:7]
        return [0.5 * (abs(f[2 * a]) + abs(f[2 * a + 1])) / area[a] for a in range(3)]
    first = rows[1]  # the end of `run 1` (rows[0] is its setup, before the meshes' first sums)
    last = rows[-1]
    moved_lo = [moved[0], moved[2], moved[4]]
    moved_hi = [moved[1], moved[3], moved[5]]
    return {"stress_start": stress(first, lo, hi), "stress_rest": stress(last, moved_lo, moved_hi),
            "kinetic_end": last[7], "steps_total": int(last[0]),
            "kinetic_history": [r[7] for r in rows[-5:]]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--strain", type=float, default=1e-4)
    ap.add_argument("--friction-deg", type=float, nargs="+", default=[0.0, 30.0])
    ap.add_argument("--restitution", type=float, default=0.3)
    ap.add_argument("--rest-steps", type=int, default=40000)
    ap.add_argument("--unbalanced", type=float, default=1e-4)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--liggghts", default=shutil.which("liggghts") or "liggghts")
    ap.add_argument("--out", default=os.path.join(ROOT, "runs", "peer-hertz"))
    ap.add_argument("--json")
    a = ap.parse_args()
    exe, pydir = grainlab_paths(a.build)
    os.makedirs(a.out, exist_ok=True)
    packing = prepare(exe, os.path.join(a.out, "prep"), a.particles, a.seed, a.restitution)
    read_packing(packing)  # validated like the other peer scripts
    results = []
    for friction in a.friction_deg:
        start, moved, steps, gl = grainlab_case(pydir, packing, friction, a.restitution, a.strain, a.rest_steps,
                                                a.unbalanced)
        with tempfile.TemporaryDirectory(prefix="liggghts-hertz-") as tmp:
            lg = liggghts_case(a.liggghts, tmp, start, moved, steps, friction, a.restitution, a.rest_steps)
        mean = lambda s: sum(s) / 3.0  # noqa: E731
        row = {"friction_deg": friction, "particles": len(start["radii"]), "strain_per_axis": a.strain,
               "dt": start["dt"], "compression_steps": steps,
               "grainlab_start_kPa": [s / 1e3 for s in start["stress"]],
               "liggghts_start_kPa": [s / 1e3 for s in lg["stress_start"]],
               "grainlab_rest_kPa": [s / 1e3 for s in gl["stress"]],
               "liggghts_rest_kPa": [s / 1e3 for s in lg["stress_rest"]],
               "grainlab_unbalanced": gl["unbalanced"], "grainlab_rest_steps": gl["rest_steps"],
               "liggghts_kinetic_end_J": lg["kinetic_end"],
               "start_ratio": mean(lg["stress_start"]) / mean(start["stress"]),
               "rest_ratio": mean(lg["stress_rest"]) / mean(gl["stress"])}
        results.append(row)
        print(f"friction {friction:4.1f} deg, {row['particles']} spheres: start p grainlab "
              f"{mean(start['stress']) / 1e3:.4f} kPa, LIGGGHTS {mean(lg['stress_start']) / 1e3:.4f} kPa "
              f"(ratio {row['start_ratio']:.6f}); after {a.strain:g} per axis at rest: grainlab "
              f"{mean(gl['stress']) / 1e3:.3f} kPa, LIGGGHTS {mean(lg['stress_rest']) / 1e3:.3f} kPa "
              f"(ratio {row['rest_ratio']:.5f})", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
