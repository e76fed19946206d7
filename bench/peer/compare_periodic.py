#!/usr/bin/env python3
"""Drained triaxial test in a periodic cell, side by side in grainlab and YADE on the same packing.

Usage: compare_periodic.py [--particles 1000] [--strain 0.08] [--rate 1.0] [--out DIR] [--doc FILE]
                           [--seeds 1,2,3] [--jobs 2]

grainlab prepares the sample (preset periodic-triaxial: the [W] grading 2-8 mm, e0 = 0.60 searched,
100 kPa) and writes its packing; both programs then start from that packing, re-equilibrate it with
their own servo and shear it at the same axial strain rate with the lateral stresses held at
100 kPa. grainlab runs with contact.moment_limit = "yade" (bending and twisting each capped at
eta min(R1, R2) |Fn|, as YADE's CohFrictPhys does), so that the laws are the same and what differs
is the engines. Writes both time series, an overlay plot and (with --doc) a Markdown section.

--seeds 1,2,3 prepares one sample per seed (sample.seed) into OUT/seed<N>/ and runs both codes on
each (--jobs seeds at a time, one thread each); the Markdown then gives, per code, the mean and
sample standard deviation over the seeds of phi and eps_v at each strain and of the peak phi up to
--peak-until, and the difference of the means beside the larger of the two scatters (agreement
is claimed only where the difference is within it).
Needs `yade` on PATH. Child processes get argument vectors, never a shell."""
import statistics
from concurrent.futures import ThreadPoolExecutor
import argparse
import csv
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
GRAINLAB = os.environ.get("GRAINLAB_BIN", os.path.join(ROOT, "build", "grainlab"))
LAW = ["--set", 'contact.moment_limit="yade"']


def run(argv):
    t = time.time()
    subprocess.run(argv, check=True)
    return time.time() - t


def read(path, eps="eps1", epsv="eps_v", phi="phi_deg"):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [(float(r[eps]), float(r[epsv]), float(r[phi])) for r in rows]


def at(series, e):
    """Linear interpolation of (eps_v, phi) at axial strain e."""
    for (e0, v0, p0), (e1, v1, p1) in zip(series, series[1:]):
        if e0 <= e <= e1 and e1 > e0:
            f = (e - e0) / (e1 - e0)
            return v0 + f * (v1 - v0), p0 + f * (p1 - p0)
    return None


STRAINS = (0.001, 0.0025, 0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08)


def one(a, out, seed):
    """Prepares the sample of `seed` and shears it in both codes into `out` (or reuses it there):
    (grainlab series, YADE series, grainlab summary, grainlab shear wall time, YADE wall time)."""
    os.makedirs(out, exist_ok=True)
    prep = os.path.join(out, "prepared")
    common = ["--set", f"sample.n_particles={a.particles}", "--threads", str(a.threads), "--quiet", *LAW]
    packing = os.path.join(prep, "packing.txt")
    gl = os.path.join(out, "grainlab")
    yade_csv = os.path.join(out, "yade.csv")
    if a.reuse:
        tg = json.load(open(os.path.join(gl, "summary.json")))["wall_seconds"]
        ty = float(open(yade_csv + ".time").read())
    else:
        run([GRAINLAB, "run", "preset:periodic-triaxial", "--out", prep, "--set", 'test.type="isotropic"',
             "--set", "output.plots=false", "--set", f"sample.seed={seed}", *common])
        tg = run([GRAINLAB, "run", "preset:periodic-triaxial", "--out", gl, "--set", f'sample.packing="{packing}"',
                  "--set", f"test.axial_strain_rate={a.rate}", "--set", f"test.final_axial_strain={a.strain}",
                  "--set", "output.plots=false", "--set", "output.vtk_every_strain=0", *common])
        ty = run(["yade", "-n", "-x", os.path.join(HERE, "yade_periodic.py"), packing, yade_csv,
                  "--strain", str(a.strain), "--rate", str(a.rate)])
        with open(yade_csv + ".time", "w") as f:
            f.write(f"{ty}\n")
    summary = json.load(open(os.path.join(gl, "summary.json")))
    return read(os.path.join(gl, "timeseries.csv")), read(yade_csv), summary, tg, ty


def seeds_table(a, results):
    """Mean +- sample std over the seeds, per code, and the difference against the scatter."""
    def ms(v):
        return f"{statistics.mean(v):.2f} ± {statistics.stdev(v):.2f}" if len(v) > 1 else f"{v[0]:.2f}"

    lines = [f"Seeds {', '.join(str(s) for s in results)}: e0 "
             + ", ".join(f"{r[2]['e0']:.3f}" for r in results.values()) + ".", "",
             "| eps1 | phi grainlab [°] | phi YADE [°] | difference [°] | within scatter | "
             "eps_v grainlab [%] | eps_v YADE [%] | difference [%] | within scatter |",
             "|---:|---:|---:|---:|---|---:|---:|---:|---|"]

    def row(label, g, y):
        d = statistics.mean(g) - statistics.mean(y)
        sc = max(statistics.stdev(g), statistics.stdev(y)) if len(g) > 1 else 0.0
        return label, ms(g), ms(y), f"{d:+.2f}", "yes" if abs(d) <= sc else "no"

    for e in STRAINS:
        if e > a.strain + 1e-12:
            break
        pts = [(at(r[0], e), at(r[1], e)) for r in results.values()]
        if not all(pg and py for pg, py in pts):
            continue
        _, gphi, yphi, dphi, okphi = row("", [pg[1] for pg, _ in pts], [py[1] for _, py in pts])
        _, gv, yv, dv, okv = row("", [100 * pg[0] for pg, _ in pts], [100 * py[0] for _, py in pts])
        lines.append(f"| {100 * e:.2g} % | {gphi} | {yphi} | {dphi} | {okphi} | {gv} | {yv} | {dv} | {okv} |")
    until = a.peak_until
    peak = lambda s: max((r for r in s if r[0] <= until), key=lambda r: r[2])
    pk = [(peak(r[0]), peak(r[1])) for r in results.values()]
    _, gp, yp, dp, okp = row("", [g[2] for g, _ in pk], [y[2] for _, y in pk])
    _, ge, ye, de, oke = row("", [100 * g[0] for g, _ in pk], [100 * y[0] for _, y in pk])
    lines += ["", f"Peak φ up to ε1 = {100 * until:g} %: grainlab {gp}°, YADE {yp}°, difference {dp}° "
              f"(within the larger scatter: {okp}); at ε1 grainlab {ge} %, YADE {ye} %.", "",
              "Shear wall times, one thread each, two runs at a time: grainlab "
              + ", ".join(f"{r[3]:.0f}" for r in results.values()) + " s; YADE "
              + ", ".join(f"{r[4]:.0f}" for r in results.values()) + " s."]
    return "\n".join(lines)


def seeds_plot(a, results, png):
    """phi and eps_v against eps1 of every seed, both codes (solid grainlab, dashed YADE)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, (seed, r) in enumerate(results.items()):
        for series, style, code in ((r[0], "-", "grainlab"), (r[1], "--", "YADE")):
            ax[0].plot([100 * x[0] for x in series], [x[2] for x in series], style, color=f"C{k}", lw=0.9,
                       label=f"{code}, seed {seed}")
            ax[1].plot([100 * x[0] for x in series], [100 * x[1] for x in series], style, color=f"C{k}", lw=0.9)
    ax[0].set_xlabel("eps1 [%]")
    ax[0].set_ylabel("mobilised friction angle phi [deg]")
    ax[1].set_xlabel("eps1 [%]")
    ax[1].set_ylabel("eps_v [%] (contraction +)")
    ax[0].legend(fontsize=7)
    for x in ax:
        x.grid(alpha=0.3)
    fig.suptitle(f"periodic cell, {a.particles} spheres, p = 100 kPa, same packing and law per seed "
                 "(solid grainlab, dashed YADE 2023.02a)", fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--strain", type=float, default=0.08)
    ap.add_argument("--rate", type=float, default=1.0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(ROOT, "runs", "peer-periodic"))
    ap.add_argument("--doc", help="write the Markdown comparison here")
    ap.add_argument("--reuse", action="store_true",
                    help="keep the runs already in --out (prepared/, grainlab/, yade.csv) and only compare; the "
                         "wall times are then those the runs recorded (grainlab's summary, YADE's yade.time)")
    ap.add_argument("--seeds", help="e.g. 1,2,3: one sample per seed into OUT/seed<N>, and the statistics")
    ap.add_argument("--jobs", type=int, default=1, help="with --seeds: seeds run at a time")
    ap.add_argument("--peak-until", type=float, default=0.045,
                    help="with --seeds: the peak phi is the largest up to this axial strain")
    a = ap.parse_args()
    if a.seeds:
        seeds = [int(x) for x in a.seeds.split(",")]
        with ThreadPoolExecutor(a.jobs) as pool:
            res = list(pool.map(lambda sd: one(a, os.path.join(a.out, f"seed{sd}"), sd), seeds))
        table = seeds_table(a, dict(zip(seeds, res)))
        seeds_plot(a, dict(zip(seeds, res)), os.path.join(a.out, "compare_periodic_seeds.png"))
        print(table)
        if a.doc:
            with open(a.doc, "w") as f:
                f.write(table + "\n")
        return 0
    g, y, summary, tg, ty = one(a, a.out, 1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for s, label in ((g, "grainlab"), (y, "YADE 2023.02a")):
        ax[0].plot([100 * r[0] for r in s], [r[2] for r in s], label=label)
        ax[1].plot([100 * r[0] for r in s], [100 * r[1] for r in s], label=label)
    ax[0].set_xlabel("eps1 [%]"); ax[0].set_ylabel("mobilised friction angle phi [deg]")
    ax[1].set_xlabel("eps1 [%]"); ax[1].set_ylabel("eps_v [%] (contraction +)")
    for x in ax:
        x.grid(alpha=0.3)
        x.legend()
    fig.suptitle(f"periodic cell, {a.particles} spheres, e0 = {summary['e0']:.3f}, p = 100 kPa, same packing and law")
    fig.tight_layout()
    png = os.path.join(a.out, "compare_periodic.png")
    fig.savefig(png, dpi=110)

    lines = ["| eps1 | phi grainlab | phi YADE | eps_v grainlab | eps_v YADE |", "|---:|---:|---:|---:|---:|"]
    for e in STRAINS:
        if e > a.strain:
            break
        pg, py = at(g, e), at(y, e)
        if pg and py:
            lines.append(f"| {100 * e:.2g} % | {pg[1]:.1f} | {py[1]:.1f} | {100 * pg[0]:+.2f} % | {100 * py[0]:+.2f} % |")
    peak = lambda s: max(s, key=lambda r: r[2])
    pg, py = peak(g), peak(y)
    lines.append("")
    lines.append(f"Peak: grainlab {pg[2]:.1f} deg at {100 * pg[0]:.2f} %, YADE {py[2]:.1f} deg at {100 * py[0]:.2f} %. "
                 f"Shear wall time: grainlab {tg:.0f} s ({a.threads} thread), YADE {ty:.0f} s.")
    table = "\n".join(lines)
    print(table)
    if a.doc:
        with open(a.doc, "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    sys.exit(main())
