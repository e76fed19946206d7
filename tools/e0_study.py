#!/usr/bin/env python3
"""The e0 study of issue 13: a loose and a dense [W] x10 sample sheared to 20 % axial strain.

    /usr/bin/python3 tools/e0_study.py run    [--runs DIR] [--exe build/grainlab] [--jobs 2] [--seeds 1,2] [--sand w|calibrated]
    /usr/bin/python3 tools/e0_study.py report [--runs DIR] [--docs docs/results] [--sand w|calibrated]

--sand calibrated runs the same study with the Karlsruhe-calibrated sand (preset
karlsruhe-calibrated, issue 13 section 3) at p = 100 kPa: e0 = 0.60 and 0.80 by the friction search
with the contact moments on; its report goes to docs/results/e0-study-calibrated-table.md and
docs/results/e0-study-calibrated/.

`run` shears every case of CASES for every seed from the `w-base` preset (2000 spheres, [W]
parameters, p = 100 kPa), one thread per run, --jobs runs at a time, into DIR/<case>-s<seed>; a
folder whose summary.json says "completed" is skipped, so an interrupted `run` picks up where it
stopped. `report` writes docs/results/e0-study-table.md (one row per run, with the targets of
issue 13 checked) and the overlays docs/results/e0-study/q.png, epsv.png and e.png.
"""
import argparse
import csv
import math
import os
import sys

from study_runs import completed, elastic_nu, residual_state, run_cases, summary, write_table  # noqa: E402 (tools/, beside this script)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# (case, label, overrides of preset:w-base). loose-moment-free cannot reach e0 = 0.80 with this grading
# in the wall box (mu_prep = 89 deg gives e = 0.749 for seed 1), so it runs at the loosest it reaches
# (mu_prep = 89 deg, no search); "compaction" with contact moments reaches 0.80.
CASES = [
    ("loose", "loose-moment-free, mu_prep 89 deg",
     ["sample.e0=0.75", 'sample.method="loose-moment-free"', "sample.prep_friction_deg=89"]),
    ("dense", "e0 = 0.60, compaction", ["sample.e0=0.60", 'sample.method="compaction"']),
    ("loose80", "e0 = 0.80, compaction with moments", ["sample.e0=0.80", 'sample.method="compaction"']),
]
COMMON = ["output.plots=false", "output.vtk_every_strain=0", "output.checkpoint_every=0.05"]
# The Karlsruhe-calibrated sand (its preset compacts without friction; here the friction search
# reaches each e0), at the study's 100 kPa.
CALIBRATED_CASES = [
    ("dense", "calibrated, e0 = 0.60", ["sample.e0=0.60", 'sample.method="compaction"', 'sample.prep_friction_deg="auto"',
                                        "test.confining_pressure=100.0e3"]),
    ("loose80", "calibrated, e0 = 0.80", ["sample.e0=0.80", 'sample.method="compaction"',
                                          'sample.prep_friction_deg="auto"', "test.confining_pressure=100.0e3"]),
]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def study(args):
    """(preset, cases, name of the report) of the --sand chosen."""
    if args.sand == "calibrated":
        return os.path.join(ROOT, "presets", "karlsruhe-calibrated.toml"), CALIBRATED_CASES, "e0-study-calibrated"
    return "preset:w-base", CASES, "e0-study"


def case_dirs(runs, seeds, cases=CASES):
    return [(case, label, seed, os.path.join(runs, f"{case}-s{seed}"), sets)
            for case, label, sets in cases for seed in seeds]


def run(args):
    seeds = [int(s) for s in args.seeds.split(",")]
    preset, cases, _ = study(args)
    return run_cases(args.exe, preset, [(folder, [f"sample.seed={seed}"] + sets + COMMON)
                                        for _, _, seed, folder, sets in case_dirs(args.runs, seeds, cases)],
                     args.jobs, nice=True)


def number(text):
    return float(text) if text not in ("", None) else float("nan")


def read_series(folder):
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    # Loops (loop_phase != 0) are not part of the monotonic curves.
    rows = [r for r in rows if r.get("loop_phase", "0") in ("0", "")]
    return {k: [number(r[k]) for r in rows] for k in rows[0]}


def end_window(series, key, frac=0.8):
    """Mean of `key` over eps1 >= frac * eps1_final (the residual window of lab/macro.hpp)."""
    eps = series["eps1"]
    vals = [v for e, v in zip(eps, series[key]) if e >= frac * eps[-1]]
    return sum(vals) / len(vals)


def fmt(v, spec):
    return "null" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def report(args):
    found = []
    _, cases, name = study(args)
    for case, label, seed, folder, _ in case_dirs(args.runs, [1, 2, 3, 4], cases):
        if completed(folder):
            found.append((case, label, seed, folder, summary(folder), read_series(folder)))
    if not found:
        print("no completed runs in", args.runs, file=sys.stderr)
        return 1
    figdir = os.path.join(args.docs, name)
    os.makedirs(figdir, exist_ok=True)
    colours = {"loose": "tab:blue", "loose80": "tab:green", "dense": "tab:red"}
    styles = ["-", "--", ":", "-."]
    for png, key, scale, ylabel in [("q.png", "q", 1e-3, "deviator q [kPa]"),
                                     ("epsv.png", "eps_v", 100.0, "volumetric strain eps_v [%] (contraction +)"),
                                     ("e.png", "e", 1.0, "void ratio e")]:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for case, label, seed, _, _, s in found:
            ax.plot([100 * v for v in s["eps1"]], [scale * v for v in s[key]], styles[(seed - 1) % 4],
                    color=colours[case], lw=1.0, label=f"{label}, seed {seed}")
        ax.set_xlabel("axial strain eps1 [%]")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(figdir, png), dpi=90)
        plt.close(fig)
    lines = ["| case | seed | e0 | Z | Z_mech | house of cards | E0 [MPa] | ν0 | E50 [MPa] | φp [°] | φres [°] | "
             "φp − φres [°] | ψmax [°] | εv at 20 % [%] | q/p res | e res | σ3 dev. max [%] | wall [s] |",
             "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for case, label, seed, _, sm, s in found:
        lines.append(
            f"| {label} | {seed} | {sm['e0']:.3f} | {sm['Z']:.2f} | {fmt(sm.get('Z_mech'), '.2f')} | "
            f"{'yes' if sm.get('house_of_cards') else 'no'} | {fmt(sm.get('E0_MPa'), '.0f')} | {fmt(elastic_nu(sm.get('nu0')), '.3f')} | "
            f"{fmt(sm.get('E50_MPa'), '.0f')} | {sm['phi_peak_deg']:.1f} | {sm['phi_res_deg']:.1f} | "
            f"{sm['phi_peak_deg'] - sm['phi_res_deg']:.1f} | {fmt(sm.get('psi_max_deg'), '.1f')} | "
            f"{100 * s['eps_v'][-1]:.2f} | {residual_state(sm)[0]:.2f} | {residual_state(sm)[1]:.3f} | "
            f"{100 * sm['lateral_stress_max_deviation']:.1f} | {sm['wall_seconds']:.0f} |")
    # The targets of issue 13, checked per pair of seeds.
    lines += ["", "| target | result |", "|---|---|"]
    by = {}
    for case, _, seed, _, sm, s in found:
        by.setdefault(seed, {})[case] = (sm, s)
    for seed, pair in sorted(by.items()):
        for loose in ("loose", "loose80"):
            if loose not in pair:
                continue
            sm, s = pair[loose]
            tag = f"seed {seed}, {loose} (e0 = {sm['e0']:.3f})"
            lines.append(f"| {tag}: contracts overall (εv > 0 at the end) | εv = {100 * s['eps_v'][-1]:.2f} % "
                         f"→ {'met' if s['eps_v'][-1] > 0 else 'missed'} |")
            d = sm["phi_peak_deg"] - sm["phi_res_deg"]
            lines.append(f"| {tag}: no peak (φp − φres < 2°) | {d:.1f}° → {'met' if d < 2 else 'missed'} |")
            if "dense" in pair:
                b_ = pair["dense"][0]
                dq = abs(residual_state(sm)[0] - residual_state(b_)[0])
                de = abs(residual_state(sm)[1] - residual_state(b_)[1])
                lines.append(f"| {tag} vs dense: same end state, q/p within 0.1 | {dq:.3f} → {'met' if dq <= 0.1 else 'missed'} |")
                lines.append(f"| {tag} vs dense: same end state, e within 0.03 | {de:.3f} → {'met' if de <= 0.03 else 'missed'} |")
    path = os.path.join(args.docs, f"{name}-table.md")
    write_table(path, lines)
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["run", "report"])
    ap.add_argument("--runs", default="/work/runs/e0-study")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--docs", default="docs/results")
    ap.add_argument("--sand", choices=["w", "calibrated"], default="w")
    args = ap.parse_args()
    return run(args) if args.command == "run" else report(args)


if __name__ == "__main__":
    sys.exit(main())
