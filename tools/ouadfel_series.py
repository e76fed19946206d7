#!/usr/bin/env python3
"""[O]'s constant mean stress series, with spheroids and with spheres of the same volume.

Usage: ouadfel_series.py OUT [--grainlab BIN] [--jobs 2] [--particles 343] [--doc docs/results]
                           [--seeds 2,3]

For each shape (prolate spheroids b/a = 0.7 of preset ouadfel-spheroids, and spheres of the same
volume prepared the same way), the grown sample is made and tested at p = 100 kPa (kappa = 25);
its packing file, unloaded by the cell's servo, gives the samples at 70, 50, 30 and 10 kPa
(--unloading frictionless, the default, is [O]'s protocol: the packing goes to the lower pressure
with friction 0, sample.packing_friction_deg = 0, and the test's friction is restored before the
test; --unloading frictional keeps the friction on, the series published before 2026-12-02) (kappa = 36, 50, 83, 250 with the same Kn), each tested at constant p to 20.5 % at an
inertial number of 1e-4. Every run is one `grainlab run` (argument vector, no shell) into
OUT/<shape>-<p>kPa. With --doc, writes the tables and plots of results/ouadfel.md there (into ouadfel/ for the
frictional unloading, ouadfel-frictionless/ for [O]'s).

--seeds 2,3 runs the whole series again for those sample seeds (sample.seed: the lattice's jitter),
each into OUT/seed<N>/ (seed 1 is OUT itself); with --doc, seeds.md there gives, per shape and
pressure, the mean and sample standard deviation over seed 1 and these, and the least-squares
slope of phi_p against log10 p of each seed (the trend with pressure a referee asks about), and
each seed's grown sample (e0, Z0, phi_p at 100 kPa). --drop spheres:3 leaves a shape's seed out of
the means (say why on the results page: e.g. a lattice that did not collapse and stayed a crystal).
"""
import statistics
import argparse
import csv
import json
import math
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

PRESSURES_KPA = [100, 70, 50, 30, 10]
SHAPES = {"spheroids": [], "spheres": ["--set", 'sample.shape={ type = "sphere" }']}
DENSITY, DIAMETER, KN, INERTIAL = 2600.0, 2e-3, 5000.0, 1e-4


def rate(p):
    """Axial strain rate of inertial number INERTIAL at mean stress p: I = rate d sqrt(rho / p)."""
    return INERTIAL / (DIAMETER * math.sqrt(DENSITY / p))


def run(args, name, sets, seed=1):
    out = os.path.join(seed_dir(args, seed), name)
    if os.path.exists(os.path.join(out, "summary.json")):
        return out
    argv = [args.grainlab, "run", "preset:ouadfel-spheroids", "--out", out, "--threads", "1", "--quiet",
            "--set", f"sample.n_particles={args.particles}", "--set", f"sample.seed={seed}", *sets]
    proc = subprocess.run(argv, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"{name}: grainlab exit {proc.returncode}\n{proc.stderr[-2000:]}")
    return out


def seed_dir(args, seed):
    return args.out if seed == 1 else os.path.join(args.out, f"seed{seed}")


def series(args, seeds):
    def base(shape_seed):
        shape, seed = shape_seed
        return run(args, f"{shape}-100kPa", SHAPES[shape] + ["--set", f"test.axial_strain_rate={rate(100e3)!r}"], seed)

    todo = [(shape, seed) for seed in seeds for shape in SHAPES]
    with ThreadPoolExecutor(args.jobs) as pool:
        bases = dict(zip(todo, pool.map(base, todo)))
        jobs = []
        for shape, seed in todo:
            packing = os.path.join(bases[(shape, seed)], "packing.txt")
            for p in PRESSURES_KPA[1:]:
                sets = ["--set", f'sample.packing="{packing}"', "--set", f"test.confining_pressure={p * 1e3!r}",
                        *(["--set", "sample.packing_friction_deg=0.0"] if args.unloading == "frictionless" else []),
                        "--set", f"test.axial_strain_rate={rate(p * 1e3)!r}"]
                jobs.append(pool.submit(run, args, f"{shape}-{p}kPa", sets, seed))
        for j in jobs:
            j.result()


def slope(xs, ys):
    """Least-squares slope of ys against xs."""
    mx, my = statistics.mean(xs), statistics.mean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def document_seeds(args, seeds, pictures):
    """seeds.md: per shape and pressure, mean +- sample std over the seeds; phi_p's slope in log10 p."""
    def ms(v, digits):
        if len(v) < 2:
            return f"{v[0]:.{digits}f}"
        return f"{statistics.mean(v):.{digits}f} ± {statistics.stdev(v):.{digits}f}"

    dropped = {tuple(d.split(":")) for d in args.drop}
    kept = {shape: [seed for seed in seeds if (shape, str(seed)) not in dropped] for shape in SHAPES}
    lines = ["Each seed's sample at 100 kPa (after growth and re-equilibration):", "",
             "| grains | seed | e0 | Z0 | φp [°] | in the means |", "|---|---:|---:|---:|---:|---|"]
    for shape in SHAPES:
        for seed in seeds:
            _, s = load(os.path.join(seed_dir(args, seed), f"{shape}-100kPa"))
            lines.append(f"| {shape} | {seed} | {s['e0']:.3f} | {s['isotropic_state']['coordination']:.2f} | "
                         f"{s['phi_peak_deg']:.1f} | {'yes' if seed in kept[shape] else 'no (--drop)'} |")
    lines += ["", f"Mean ± sample standard deviation over the seeds kept "
              f"({'; '.join(f'{sh}: ' + ', '.join(map(str, kept[sh])) for sh in SHAPES)}).", "",
             "| grains | p [kPa] | κ | e0 | Z0 | φp [°] | ε1 at peak [%] | φ at 20.5 % [°] | ψmax [°] | εv at 20.5 % [%] |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    slopes = {}
    for shape in SHAPES:
        per_seed = {seed: [] for seed in kept[shape]}
        for p in PRESSURES_KPA:
            vals = {k: [] for k in ("e0", "Z0", "phi", "epk", "phiend", "psi", "ev")}
            for seed in kept[shape]:
                rows, s = load(os.path.join(seed_dir(args, seed), f"{shape}-{p}kPa"))
                last = rows[-1]
                vals["e0"].append(s["e0"])
                vals["Z0"].append(s["isotropic_state"]["coordination"])
                vals["phi"].append(s["phi_peak_deg"])
                vals["epk"].append(100 * s["eps1_at_peak"])
                vals["phiend"].append(number(last["phi_deg"]))
                vals["psi"].append(s["psi_max_deg"])
                vals["ev"].append(100 * number(last["eps_v"]))
                per_seed[seed].append((math.log10(p), s["phi_peak_deg"]))
            lines.append(f"| {shape} | {p} | {KN / (p * 1e3 * DIAMETER):.0f} | {ms(vals['e0'], 3)} | {ms(vals['Z0'], 2)} | "
                         f"{ms(vals['phi'], 1)} | {ms(vals['epk'], 1)} | {ms(vals['phiend'], 1)} | {ms(vals['psi'], 1)} | "
                         f"{ms(vals['ev'], 2)} |")
        slopes[shape] = {seed: slope([x for x, _ in per_seed[seed]], [y for _, y in per_seed[seed]]) for seed in kept[shape]}
    lines += ["", "Slope of φp against log10 p (degrees per decade of p, 10 → 100 kPa), per seed:", "",
              "| grains | " + " | ".join(f"seed {seed}" for seed in seeds) + " | mean ± std |",
              "|---|" + "---:|" * (len(seeds) + 1)]
    for shape in SHAPES:
        v = slopes[shape]
        lines.append(f"| {shape} | " + " | ".join(f"{v[seed]:+.2f}" if seed in v else "—" for seed in seeds)
                     + f" | {ms(list(v.values()), 2)} |")
    with open(os.path.join(pictures, "seeds.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def load(folder):
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    return rows, summary


def number(text):
    return float(text) if text else float("nan")


def document(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pictures = os.path.join(args.doc, "ouadfel" if args.unloading == "frictional" else "ouadfel-frictionless")
    os.makedirs(pictures, exist_ok=True)
    table = []
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
    for row_axes, shape in zip(axes, SHAPES):
        for p in PRESSURES_KPA:
            rows, s = load(os.path.join(args.out, f"{shape}-{p}kPa"))
            eps1 = [100 * number(r["eps1"]) for r in rows]
            label = f"p = {p} kPa (kappa = {KN / (p * 1e3 * DIAMETER):.0f})"
            row_axes[0].plot(eps1, [number(r["q"]) / number(r["p"]) for r in rows], lw=1.1, label=label)
            row_axes[1].plot(eps1, [100 * number(r["eps_v"]) for r in rows], lw=1.1, label=label)
            row_axes[2].plot(eps1, [number(r["Z"]) for r in rows], lw=1.1, label=label)
            table.append((shape, p, KN / (p * 1e3 * DIAMETER), s))
        row_axes[0].set_ylabel(f"{shape}: q/p")
        row_axes[1].set_ylabel(f"{shape}: eps_v [%] (contraction > 0)")
        row_axes[2].set_ylabel(f"{shape}: coordination Z")
        for ax in row_axes:
            ax.set_xlabel("axial strain eps1 [%]")
            ax.grid(alpha=0.3)
        row_axes[0].legend(fontsize=8)
    fig.suptitle(f"[O] constant-p series, {args.particles} grains, periodic cell, mu = 0.5, Ks = Kn, "
                 f"{args.unloading} unloading")
    fig.tight_layout()
    fig.savefig(os.path.join(pictures, "series.png"), dpi=100)
    plt.close(fig)

    # Growth curve of the spheroids (and the spheres' single relaxation).
    _, s = load(os.path.join(args.out, "spheroids-100kPa"))
    curve = s["growth_curve"]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    e = [g["eccentricity"] for g in curve]
    ax.errorbar(e, [g["Z"] for g in curve], yerr=[g["Z_std"] for g in curve], marker="o", ms=3, capsize=2,
                label="Z (bars: spread over the grains)")
    ax.set_xlabel("eccentricity (a - b)/(a + b)")
    ax.set_ylabel("coordination number Z")
    ax2 = ax.twinx()
    ax2.plot(e, [g["packing_fraction"] for g in curve], "r--", marker="s", ms=3, label="packing fraction")
    ax2.set_ylabel("packing fraction", color="r")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("growth of aligned prolate spheroids at p = 100 kPa, mu = 0 (kappa = 25)")
    fig.tight_layout()
    fig.savefig(os.path.join(pictures, "growth.png"), dpi=100)
    plt.close(fig)

    lines = ["| grains | p [kPa] | κ | e0 | Z0 | φp [°] | ε1 at peak [%] | φ at 20.5 % [°] | ψmax [°] | εv at 20.5 % [%] | Z at 20.5 % | steps | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for shape, p, kappa, s in table:
        rows, _ = load(os.path.join(args.out, f"{shape}-{p}kPa"))
        last = rows[-1]
        lines.append(f"| {shape} | {p} | {kappa:.0f} | {s['e0']:.3f} | {s['isotropic_state']['coordination']:.2f} | "
                     f"{s['phi_peak_deg']:.1f} | {100 * s['eps1_at_peak']:.1f} | {number(last['phi_deg']):.1f} | "
                     f"{s['psi_max_deg']:.1f} | {100 * number(last['eps_v']):.2f} | {number(last['Z']):.2f} | "
                     f"{s['steps']} | {s['wall_seconds']:.0f} |")
    growth = ["| eccentricity | Z | Z spread (std) | packing fraction |", "|---|---|---|---|"]
    for g in curve:
        growth.append(f"| {g['eccentricity']:.3f} | {g['Z']:.2f} | {g['Z_std']:.2f} | {g['packing_fraction']:.4f} |")
    with open(os.path.join(pictures, "tables.md"), "w") as f:
        f.write("\n".join(lines) + "\n\n" + "\n".join(growth) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--grainlab", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "grainlab"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--particles", type=int, default=343)
    ap.add_argument("--unloading", choices=("frictionless", "frictional"), default="frictionless",
                    help="how the 100 kPa packing goes to the lower pressures ([O]: frictionless)")
    ap.add_argument("--doc", help="write results/ouadfel tables and plots into this folder")
    ap.add_argument("--seeds", default="", help="further sample seeds (e.g. 2,3), each into OUT/seed<N>")
    ap.add_argument("--drop", action="append", default=[], metavar="SHAPE:SEED",
                    help="leave this shape's seed out of seeds.md's means (it is still listed)")
    args = ap.parse_args()
    args.grainlab = os.path.abspath(args.grainlab)
    seeds = [1] + [int(x) for x in args.seeds.split(",") if x.strip() and int(x) != 1]
    os.makedirs(args.out, exist_ok=True)
    series(args, seeds)
    if args.doc:
        document(args)
        if len(seeds) > 1:
            document_seeds(args, seeds, os.path.join(args.doc, "ouadfel" if args.unloading == "frictional"
                                                     else "ouadfel-frictionless"))


if __name__ == "__main__":
    main()
