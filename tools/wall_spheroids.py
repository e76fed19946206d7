#!/usr/bin/env python3
"""Drained triaxial tests in the wall box with [W]'s grading: spheres against prolate spheroids
(issue 11; published in docs/results/ouadfel.md, "Wall box with spheroids of [W]'s grading").

    /usr/bin/python3 tools/wall_spheroids.py run    [--runs DIR] [--exe build/grainlab] [--jobs 2]
    /usr/bin/python3 tools/wall_spheroids.py report [--runs DIR] [--docs docs/results]

`run` shears preset w-base reduced to 1000 grains, compacted without friction (the densest state
of each shape), p = 100 kPa, to 15 % axial strain, for spheres and for spheroids b/a = 0.7 of the
same volume distribution (random orientations), each with the [W] contact moments (beta 0.15,
eta 1) and without them (beta 0), one thread per run, into DIR/<case>; a completed case is skipped.
`report` prints the table and writes docs/results/ouadfel/wall_q.png and wall_epsv.png.
"""
import argparse
import csv
import json
import os
import sys

from study_runs import completed, run_cases  # noqa: E402 (tools/, beside this script)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SPHEROID = 'sample.shape={type="ellipsoid", elongation=0.7, orientation="random"}'
CASES = [
    ("spheres", "spheres, β = 0.15", []),
    ("spheroids", "spheroids b/a = 0.7, β = 0.15", [SPHEROID]),
    ("spheres-beta0", "spheres, β = 0 (no moments)", ["contact.beta=0"]),
    ("spheroids-beta0", "spheroids b/a = 0.7, β = 0 (no moments)", [SPHEROID, "contact.beta=0"]),
]
COMMON = ["sample.n_particles=1000", "sample.prep_friction_deg=0", "test.final_axial_strain=0.15",
          "output.vtk_every_strain=0.05"]


def run(a):
    return run_cases(a.exe, "preset:w-base", [(os.path.join(a.runs, c), COMMON + sets) for c, _, sets in CASES], a.jobs)


def fmt(v, digits=1):
    return "null" if v is None else f"{v:.{digits}f}"


def report(a):
    out_dir = os.path.join(a.docs, "ouadfel")
    os.makedirs(out_dir, exist_ok=True)
    lines = ["| case | e0 | Z | Z_mech | φp [°] | ε1 at peak [%] | ψmax [°] | φres [°] | e at end | E50 [MPa] | "
             "mean rotation [°] | σ3 dev. max [%] | wall [s] |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    fig_q, ax_q = plt.subplots(figsize=(7, 4.5))
    fig_v, ax_v = plt.subplots(figsize=(7, 4.5))
    for case, label, _ in CASES:
        folder = os.path.join(a.runs, case)
        if not completed(folder):
            lines.append(f"| {label} | not run | | | | | | | | | | | |")
            continue
        with open(os.path.join(folder, "summary.json")) as f:
            s = json.load(f)
        with open(os.path.join(folder, "timeseries.csv")) as f:
            rows = list(csv.DictReader(f))
        eps1 = [100 * float(r["eps1"]) for r in rows]
        dev = s.get("lateral_stress_max_deviation")
        lines.append(
            f"| {label} | {s['e0']:.3f} | {s['Z']:.2f} | {fmt(s.get('Z_mech'), 2)} | {fmt(s.get('phi_peak_deg'))} | "
            f"{fmt(100 * s['eps1_at_peak'] if s.get('eps1_at_peak') is not None else None)} | "
            f"{fmt(s.get('psi_max_deg'))} | {fmt(s.get('phi_res_deg'))} | {fmt(s.get('residual_void_ratio', s.get('cs_void_ratio')), 3)} | "
            f"{fmt(s.get('E50_MPa'), 0)} | {fmt(s.get('rotation_mean_deg'))} | "
            f"{fmt(100 * dev if dev is not None else None)} | {s['wall_seconds']:.0f} |")
        style = "-" if "spheroid" in case else "--"
        colour = "tab:red" if "beta0" not in case else "tab:blue"
        ax_q.plot(eps1, [float(r["phi_deg"]) for r in rows], style, color=colour, lw=1.0, label=label)
        ax_v.plot(eps1, [100 * float(r["eps_v"]) for r in rows], style, color=colour, lw=1.0, label=label)
    ax_q.set_ylabel("mobilised friction angle φ [°]")
    ax_v.set_ylabel("volumetric strain εv [%] (contraction > 0)")
    for fig, ax, name in ((fig_q, ax_q, "wall_phi.png"), (fig_v, ax_v, "wall_epsv.png")):
        ax.set_xlabel("axial strain ε1 [%]")
        ax.set_title("wall box, [W] grading, 1000 grains, p = 100 kPa")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, name), dpi=100)
    print("\n".join(lines))
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=["run", "report"])
    ap.add_argument("--runs", default=os.path.join(ROOT, "runs", "wall-spheroids"))
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "grainlab"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    return run(a) if a.what == "run" else report(a)


if __name__ == "__main__":
    sys.exit(main())
