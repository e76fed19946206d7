#!/usr/bin/env python3
"""Side-by-side drained triaxial test in grainlab and YADE on the same packing.

Usage: compare_triaxial.py [--packing FILE | --particles N] [--strain 0.02] [--rate 1.0] [--out DIR]

Without --packing, grainlab prepares a dense isotropic sample of the [W] grading (2-8 mm) at
100 kPa (frictionless compaction) and writes its packing.txt; both programs then start from that
packing, re-equilibrate it at 100 kPa with their own law (Ec 30 GPa, ks/kn 0.3, mu 30 deg,
beta 0.15, eta 1, alpha 0.3, smooth walls) and shear it at the same constant platen speed.
Prints phi, eps_v and Z against eps1 for both, and the wall-clock times. Needs `yade` on PATH.
Known law differences (see yade_triaxial.py): YADE limits bending and twisting separately by
eta*min(R1,R2)*|Fn|, grainlab the whole moment by eta*(R1+R2)/2*|Fn|."""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
GRAINLAB = os.path.join(ROOT, "build", "grainlab")


def grainlab_run(args):
    subprocess.run([GRAINLAB, "run", "preset:quick-triaxial", "--quiet", "--set", "output.plots=false", *args],
                   check=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--packing")
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--strain", type=float, default=0.02)
    ap.add_argument("--rate", type=float, default=1.0)
    ap.add_argument("--out", default=os.path.join(ROOT, "runs", "peer"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    packing = a.packing
    if not packing:
        prep = os.path.join(a.out, "prep")
        grainlab_run(["--out", prep, "--set", f"sample.n_particles={a.particles}", "--set", 'test.type="isotropic"'])
        packing = os.path.join(prep, "packing.txt")

    t0 = time.time()
    gl_dir = os.path.join(a.out, "grainlab")
    grainlab_run(["--out", gl_dir, "--set", f'sample.packing="{packing}"', "--set", f"test.axial_strain_rate={a.rate}",
                  "--set", f"test.final_axial_strain={a.strain}", "--set", "output.record_every_strain=0.002"])
    t_gl = time.time() - t0

    t0 = time.time()
    yade_csv = os.path.join(a.out, "yade.csv")
    subprocess.run(["yade", "-n", "-x", os.path.join(HERE, "yade_triaxial.py"), packing, yade_csv,
                    "--strain", str(a.strain), "--rate", str(a.rate)], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t_yade = time.time() - t0

    with open(os.path.join(gl_dir, "timeseries.csv")) as f:
        gl = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    with open(yade_csv) as f:
        yd = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    summary = json.load(open(os.path.join(gl_dir, "summary.json")))

    def at(rows, eps):
        return min(rows, key=lambda r: abs(r["eps1"] - eps))

    print(f"packing: {packing} ({summary['n_particles']} spheres, e0 = {summary['e0']:.4f})")
    print(f"{'eps1 %':>7} | {'phi grainlab':>12} {'phi YADE':>9} | {'eps_v % gl':>10} {'eps_v % YADE':>12} | {'Z gl':>5} {'Z YADE':>6}")
    steps = 10
    for i in range(1, steps + 1):
        eps = a.strain * i / steps
        g, y = at(gl, eps), at(yd, eps)
        print(f"{100 * eps:7.2f} | {g['phi_deg']:12.2f} {y['phi_deg']:9.2f} | {100 * g['eps_v']:10.3f} {100 * y['eps_v']:12.3f} | "
              f"{g['Z']:5.2f} {y['Z']:6.2f}")
    print(f"wall time: grainlab {t_gl:.1f} s ({summary['threads']} threads, whole run), YADE {t_yade:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
