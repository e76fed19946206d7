#!/usr/bin/env python3
"""Loose samples made by deposition under gravity (issue 27 section 2): e, Z, Z_mech, rattlers and
the fabric anisotropy after preparation at 100 kPa, against the densest state of the same grading,
for two sands and several rain frictions, with replicate seeds (docs/results/deposition.md).

    /usr/bin/python3 tools/deposition_study.py run    [--runs runs/deposition-study] [--exe build/grainlab]
                                                      [--jobs 2] [--seeds 1,2,3]
    /usr/bin/python3 tools/deposition_study.py report [--runs runs/deposition-study] [--seeds 1,2,3]
                                                      [--docs docs/results]

`run` prepares every case whose folder is not completed (isotropic test: the run stops after the
preparation at p; one thread each, --jobs at a time; an interrupted `run` resumes). With --shear it
also shears the deposited loose and the densest sample of the uniform sand to 20 % (drained
triaxial). `report` writes docs/results/deposition-table.md (one row per run and the seed means)
and docs/results/deposition/*.png; a case that did not complete is listed as missing, never filled.
"""
import argparse
import csv
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import completed, run_cases, summary, write_table  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
P = "test.confining_pressure=100.0e3"
PREP = ['test.type="isotropic"', P, "output.vtk_every_strain=0", "output.plots=false"]
# Sands: (name, config, n_particles, label). "uniform": tests/data/small-triaxial.toml (uniform
# 4-6 mm, the [W] law with eta = 1) at 1000 grains, the sand of docs/laboratory.md 1.7-1.8;
# "karlsruhe": the calibrated Karlsruhe sand (preset karlsruhe-calibrated: [W] x10 grading 2-8 mm,
# eta = 0.286, 2000 grains).
SANDS = [
    ("uniform", os.path.join(ROOT, "tests", "data", "small-triaxial.toml"), 1000,
     "uniform 4-6 mm, [W] law (mu 30 deg, beta 0.15, eta 1), 1000 spheres"),
    ("karlsruhe", "preset:karlsruhe-calibrated", 2000,
     "calibrated Karlsruhe sand ([W] x10 grading 2-8 mm, mu 22.56 deg, eta 0.286), 2000 spheres"),
]
# Preparations: (case, label, sets). The densest state: frictionless compaction in the same box.
RAIN = {"uniform": (0.0, 10.0, 20.0, 30.0), "karlsruhe": (0.0, 10.0, 22.56)}
DROP = "sample.drop_height=0.01"


def preparations(sand):
    yield "densest", "frictionless compaction", ['sample.method="compaction"', "sample.prep_friction_deg=0"]
    for mu in RAIN[sand]:
        yield (f"dep{mu:g}", f"deposition, rain friction {mu:g} deg",
               ['sample.method="deposition"', f"sample.prep_friction_deg={mu}", DROP])


SHEAR = ['test.type="triaxial"', P, "test.final_axial_strain=0.2", 'test.axial_strain_rate="auto"',
         "output.vtk_every_strain=0", "output.plots=false"]
SHEAR_CASES = ("densest", "dep10")


def cases(seeds, shear=False):
    """(sand, case, label, seed, folder, config, sets)."""
    for sand, config, n, _ in SANDS:
        for case, label, sets in preparations(sand):
            for seed in seeds:
                yield (sand, case, label, seed, f"{sand}-{case}_s{seed}", config,
                       PREP + sets + [f"sample.n_particles={n}", f"sample.seed={seed}"])
    if shear:
        sand, config, n, _ = SANDS[0]
        for case, label, sets in preparations(sand):
            if case not in SHEAR_CASES:
                continue
            for seed in seeds:
                yield (sand, "shear-" + case, label, seed, f"{sand}-shear-{case}_s{seed}", config,
                       SHEAR + sets + [f"sample.n_particles={n}", f"sample.seed={seed}"])


def run(a):
    by_config = {}
    for sand, case, label, seed, name, config, sets in cases(a.seeds, a.shear):
        by_config.setdefault(config, []).append((os.path.join(a.runs, name), sets))
    for config, todo in by_config.items():
        run_cases(a.exe, config, todo, a.jobs)
    return 0


def mean_sd(values, digits=3):
    v = [x for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    if not v:
        return "null"
    if len(v) == 1:
        return f"{v[0]:.{digits}f} (1 seed)"
    return f"{statistics.mean(v):.{digits}f} ± {statistics.stdev(v):.{digits}f}"


def f3(v, digits=3):
    return "null" if v is None else f"{v:.{digits}f}"


def prepared(s):
    fab = s.get("fabric_after_preparation") or {}
    dep = s.get("deposition") or {}
    return {
        "e0": s.get("e0"), "Z": s.get("Z"), "Z_mech": s.get("Z_mech"), "rattlers": s.get("rattler_fraction"),
        "a_r_zz": fab.get("a_r_zz"), "a_r": fab.get("a_r"),
        "settled_e": dep.get("settled_void_ratio"), "settled_Z": dep.get("settled_Z"),
        "settled_a_r_zz": dep.get("settled_a_r_zz"), "wall": s.get("wall_seconds"),
        "house_of_cards": s.get("house_of_cards"),
    }


def series(folder):
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) if r[k] not in ("", None) else math.nan for r in rows] for k in rows[0]}


def report(a):
    os.makedirs(os.path.join(a.docs, "deposition"), exist_ok=True)
    rows, missing, by_case = [], [], {}
    header = ("| sand | preparation | seed | settled e | settled Z | settled a_r_zz | e at 100 kPa | Z | Z_mech | "
              "rattlers | a_r_zz | a_r | e − e_densest (same seed) | wall [s] |")
    rows = [header, "|" + "---|" * 14]
    densest = {}
    all_cases = [c for c in cases(a.seeds) if not c[1].startswith("shear-")]
    for sand, case, label, seed, name, config, sets in all_cases:
        folder = os.path.join(a.runs, name)
        if case == "densest" and completed(folder):
            densest[(sand, seed)] = summary(folder).get("e0")
    for sand, case, label, seed, name, config, sets in all_cases:
        folder = os.path.join(a.runs, name)
        if not completed(folder):
            missing.append(name)
            continue
        v = prepared(summary(folder))
        d = densest.get((sand, seed))
        v["excess"] = None if d is None or v["e0"] is None else v["e0"] - d
        by_case.setdefault((sand, case, label), []).append(v)
        rows.append(f"| {sand} | {label} | {seed} | {f3(v['settled_e'])} | {f3(v['settled_Z'], 2)} | "
                    f"{f3(v['settled_a_r_zz'], 2)} | {f3(v['e0'])} | {f3(v['Z'], 2)} | {f3(v['Z_mech'], 2)} | "
                    f"{f3(v['rattlers'], 2)} | {f3(v['a_r_zz'], 2)} | {f3(v['a_r'], 2)} | {f3(v['excess'])} | "
                    f"{f3(v['wall'], 0)} |")
    rows.append("")
    rows.append("Seed means ± standard deviations:")
    rows.append("")
    rows.append("| sand | preparation | seeds | e at 100 kPa | Z | Z_mech | rattlers | a_r_zz | e − e_densest | "
                "Z ≥ 3 and e − e_densest ≥ 0.1 in every seed |")
    rows.append("|" + "---|" * 10)
    for (sand, case, label), vs in by_case.items():
        ok = all(v["Z"] is not None and v["Z"] >= 3 and v["excess"] is not None and v["excess"] >= 0.1 for v in vs)
        rows.append(f"| {sand} | {label} | {len(vs)} | {mean_sd([v['e0'] for v in vs])} | "
                    f"{mean_sd([v['Z'] for v in vs], 2)} | {mean_sd([v['Z_mech'] for v in vs], 2)} | "
                    f"{mean_sd([v['rattlers'] for v in vs], 2)} | {mean_sd([v['a_r_zz'] for v in vs], 2)} | "
                    f"{mean_sd([v['excess'] for v in vs])} | {'—' if case == 'densest' else ('yes' if ok else 'no')} |")
    write_table(os.path.join(a.docs, "deposition-table.md"), rows)

    # Fabric and coordination against the rain friction.
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for sand, _, _, _ in SANDS:
        xs, es, zs, ars, sx, sz, sar = [], [], [], [], [], [], []
        for (s2, case, label), vs in by_case.items():
            if s2 != sand or case == "densest":
                continue
            mu = float(case[3:])
            for v in vs:
                xs.append(mu); es.append(v["e0"]); zs.append(v["Z"]); ars.append(v["a_r_zz"])
                sx.append(mu); sz.append(v["settled_Z"]); sar.append(v["settled_a_r_zz"])
        if not xs:
            continue
        m = "o" if sand == "uniform" else "s"
        axes[0].plot(xs, es, m, label=f"{sand}: at 100 kPa")
        axes[1].plot(xs, zs, m, label=f"{sand}: at 100 kPa")
        axes[1].plot(sx, sz, m, mfc="none", label=f"{sand}: settled bed")
        axes[2].plot(xs, ars, m, label=f"{sand}: at 100 kPa")
        axes[2].plot(sx, sar, m, mfc="none", label=f"{sand}: settled bed")
        dens = [v["e0"] for (s2, c, _), vs in by_case.items() if s2 == sand and c == "densest" for v in vs]
        if dens:
            axes[0].axhline(statistics.mean(dens), ls="--", lw=0.8, color=axes[0].lines[-1].get_color(),
                            label=f"{sand}: densest")
    axes[1].axhline(3, color="k", lw=0.6, ls=":")
    axes[2].axhline(0, color="k", lw=0.6, ls=":")
    for ax, yl in zip(axes, ("void ratio e", "coordination Z", "a_r_zz (vertical contact preference > 0)")):
        ax.set_xlabel("rain friction [deg]")
        ax.set_ylabel(yl)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.docs, "deposition", "preparation.png"), dpi=110)
    plt.close(fig)

    # Shearing of the uniform sand: deposited loose against densest.
    shear = [c for c in cases(a.seeds, True) if c[1].startswith("shear-")]
    if any(completed(os.path.join(a.runs, c[4])) for c in shear):
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        lines = ["| preparation | seed | e0 | Z | φp [°] | ε1 at peak [%] | ψmax [°] | εv at 20 % [%] | "
                 "q/p end | e end | wall [s] |", "|" + "---|" * 11]
        colours = {"shear-densest": "tab:blue", "shear-dep10": "tab:red"}
        for sand, case, label, seed, name, config, sets in shear:
            folder = os.path.join(a.runs, name)
            if not completed(folder):
                missing.append(name)
                continue
            s = summary(folder)
            t = series(folder)
            axes[0].plot([100 * x for x in t["eps1"]], [y / 1e3 for y in t["q"]], color=colours[case], lw=0.9,
                         label=f"{label}, seed {seed}")
            axes[1].plot([100 * x for x in t["eps1"]], [100 * y for y in t["eps_v"]], color=colours[case], lw=0.9)
            ev = t["eps_v"][-1] if t["eps_v"] else None
            lines.append(f"| {label} | {seed} | {f3(s.get('e0'))} | {f3(s.get('Z'), 2)} | {f3(s.get('phi_peak_deg'), 1)} | "
                         f"{f3(None if s.get('eps1_at_peak') is None else 100 * s['eps1_at_peak'], 1)} | "
                         f"{f3(s.get('psi_max_deg'), 1)} | {f3(None if ev is None else 100 * ev, 2)} | "
                         f"{f3(s.get('end_q_over_p'), 3)} | {f3(s.get('end_void_ratio'))} | {f3(s.get('wall_seconds'), 0)} |")
        axes[0].set_ylabel("q [kPa]")
        axes[1].set_ylabel("εv [%] (compression > 0)")
        for ax in axes:
            ax.set_xlabel("ε1 [%]")
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(a.docs, "deposition", "shear.png"), dpi=110)
        plt.close(fig)
        write_table(os.path.join(a.docs, "deposition-shear-table.md"), lines)
    if missing:
        print("missing (not completed):", ", ".join(missing))
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["run", "report"])
    ap.add_argument("--runs", default=os.path.join(ROOT, "runs", "deposition-study"))
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "grainlab"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--shear", action="store_true", help="also shear the uniform sand's densest and dep10 samples")
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    a.seeds = [int(s) for s in a.seeds.split(",")]
    return run(a) if a.command == "run" else report(a)


if __name__ == "__main__":
    sys.exit(main())
