#!/usr/bin/env python3
"""LIGGGHTS peer of `grainlab bench triaxial-iso`: the same packing, time step and number of steps.

Usage:
    /usr/bin/python3 bench/peer/liggghts_bench.py PACKING --steps S --dt DT [--warmup 200] [--procs 1]

PACKING is the scene's grainlab packing file (~/.cache/grainlab/triaxial-iso-N.txt, read by
packing_file.py). The script writes a LIGGGHTS data file and input script into a scratch folder,
runs Debian's `liggghts` (3.8; with --procs > 1 under `mpirun -np P`) with an argument vector, and
reads LIGGGHTS' own "Loop time" of the timed `run`.

The closest law LIGGGHTS 3.8 has to grainlab's [W] law: `model hooke/stiffness tangential history
rolling_friction epsd2` - a linear normal spring kn and tangential spring kt = 0.3 kn with a
Coulomb limit, and an elastic-plastic rolling spring (Iwashita-Oda) capped at mu_r * R * Fn.
Differences in physics (not in the work per contact): kn is one constant for every pair (grainlab:
Ec * 2 R1 R2 / (R1 + R2), here the value for two d50 spheres), a viscous dashpot instead of
Cundall's local damping (LIGGGHTS has none), no twisting moment, and the six walls are fixed planes
(`fix wall/gran ... primitive`) instead of stress servos - the servos' cost is a few sums per
step in both programs. Density 2600 kg/m3, no gravity.

Prints one JSON line: scene, program, n_particles, n_contacts (sphere-sphere, at the end), steps, seconds, particle_steps_per_s, threads (MPI processes), dt.
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from packing_file import read_packing  # noqa: E402


def write_inputs(folder, planes, spheres, steps, warmup, dt, young, poisson_ratio_kt, mu, mu_r, density):
    xlo, xhi, ylo, yhi, zlo, zhi = planes
    # A margin around the walls: LIGGGHTS' simulation box must contain every atom strictly.
    pad = 0.05 * max(xhi - xlo, yhi - ylo, zhi - zlo)
    with open(os.path.join(folder, "spheres.data"), "w") as f:
        f.write("grainlab packing for LIGGGHTS\n\n")
        f.write(f"{len(spheres)} atoms\n1 atom types\n\n")
        f.write(f"{xlo - pad!r} {xhi + pad!r} xlo xhi\n{ylo - pad!r} {yhi + pad!r} ylo yhi\n"
                f"{zlo - pad!r} {zhi + pad!r} zlo zhi\n\nAtoms\n\n")
        for i, (r, x, y, z) in enumerate(spheres, start=1):
            # atom_style granular: atom-ID atom-type diameter density x y z
            f.write(f"{i} 1 {2.0 * r!r} {density!r} {x!r} {y!r} {z!r}\n")
    d50 = sorted(2.0 * s[0] for s in spheres)[len(spheres) // 2]
    kn = young * d50 / 2.0  # Ec * 2 R1 R2 / (R1 + R2) for two spheres of diameter d50
    kt = poisson_ratio_kt * kn
    mass = density * math.pi / 6.0 * d50 ** 3
    # A light dashpot (5 % of critical for two d50 spheres), standing in for Cundall damping.
    gamma_n = 0.05 * 2.0 * math.sqrt(kn * mass / 2.0) / (mass / 2.0)
    law = "model hooke/stiffness tangential history rolling_friction epsd2"
    walls = [("xplane", xlo), ("xplane", xhi), ("yplane", ylo), ("yplane", yhi), ("zplane", zlo), ("zplane", zhi)]
    lines = [
        "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
        "communicate single vel yes", "units si",
        "read_data spheres.data",
        f"neighbor {0.1 * d50!r} bin", "neigh_modify delay 0",
        f"fix kn all property/global kn peratomtypepair 1 {kn!r}",
        f"fix kt all property/global kt peratomtypepair 1 {kt!r}",
        f"fix gn all property/global gamman peratomtypepair 1 {gamma_n!r}",
        f"fix gt all property/global gammat peratomtypepair 1 {gamma_n!r}",
        f"fix cf all property/global coefficientFriction peratomtypepair 1 {mu!r}",
        f"fix crf all property/global coefficientRollingFriction peratomtypepair 1 {mu_r!r}",
        f"fix ym all property/global youngsModulus peratomtype {young!r}",
        "fix pr all property/global poissonsRatio peratomtype 0.3",
        "fix cr all property/global coefficientRestitution peratomtypepair 1 0.9",
        f"pair_style gran {law}",
        "pair_coeff * *",
        f"timestep {dt!r}",
    ]
    for k, (kind, pos) in enumerate(walls):
        lines.append(f"fix w{k} all wall/gran {law} primitive type 1 {kind} {pos!r}")
    lines += [
        "fix integr all nve/sphere",
        # Sphere-sphere contacts (contact/atom counts each contact at both spheres), printed with
        # the thermo output at the end of each run.
        "compute cn all contact/atom", "compute zsum all reduce sum c_cn",
        "thermo 1000000", "thermo_style custom step atoms c_zsum",
        f"run {warmup}",
        f"run {steps}",
    ]
    with open(os.path.join(folder, "in.bench"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("packing")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--warmup", type=int, default=200)
    ap.add_argument("--dt", type=float, required=True)
    ap.add_argument("--procs", type=int, default=1)
    ap.add_argument("--exe", default=shutil.which("liggghts") or "liggghts")
    a = ap.parse_args()
    planes, spheres = read_packing(a.packing)
    with tempfile.TemporaryDirectory(prefix="liggghts-bench-") as tmp:
        # [W] law: Ec = 30 GPa, ks/kn = 0.3, mu = 30 deg; rolling coefficient = eta * (moment arm
        # over R) for eta = 1 with grainlab's arm (R1 + R2) / 2 = R for equal spheres.
        write_inputs(tmp, planes, spheres, a.steps, a.warmup, a.dt, 30e9, 0.3, math.tan(math.radians(30.0)), 1.0, 2600.0)
        argv = [a.exe, "-in", "in.bench", "-log", "log.bench", "-echo", "none", "-screen", "none"]
        if a.procs > 1:
            argv = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(a.procs), *argv]
        proc = subprocess.run(argv, cwd=tmp, capture_output=True, text=True, timeout=3600)
        log = open(os.path.join(tmp, "log.bench")).read() if os.path.exists(os.path.join(tmp, "log.bench")) else ""
        loops = re.findall(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", log)
        if proc.returncode != 0 or len(loops) < 2:
            sys.stderr.write(f"liggghts failed (exit {proc.returncode}):\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
                             f"{log[-3000:]}\n")
            return 1
        seconds, procs, steps, atoms = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2]), int(loops[-1][3])
        # The thermo line printed at the end of the timed run: "step atoms zsum".
        rows = re.findall(r"^\s*(\d+)\s+(\d+)\s+([0-9.eE+-]+)\s*$", log, flags=re.M)
        contacts = int(round(float(rows[-1][2]) / 2.0)) if rows else None
    if atoms != len(spheres):
        sys.stderr.write(f"liggghts lost particles: {atoms} of {len(spheres)} left at the end (time step too large "
                         "for its stiffness?)\n")
        return 1
    print(json.dumps({"scene": "triaxial-iso", "program": "liggghts", "n_particles": atoms, "n_contacts": contacts,
                      "steps": steps, "seconds": seconds, "particle_steps_per_s": steps * atoms / seconds,
                      "threads": procs, "dt": a.dt}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
