#!/usr/bin/env python3
"""What the Karlsruhe-calibrated sand predicts away from its calibration (issue 13 section 3).

    /usr/bin/python3 tools/karlsruhe_checks.py run    [--runs DIR] [--exe build/grainlab] [--jobs 2]
    /usr/bin/python3 tools/karlsruhe_checks.py report [--runs DIR] [--docs docs/results]

`run` shears preset karlsruhe-calibrated (2000 spheres, walls, densest state) at p = 100, 200 (the
calibration's pressure) and 400 kPa, a loose sample of it (e0 = 0.80, friction search with the
contact moments on) at 200 kPa, and the same parameters in the periodic cell at e0 = 0.53, each to
20 % axial strain on one thread, --jobs at a time, into DIR/<case>; a completed case is skipped.
`report` writes docs/results/calibration-karlsruhe-checks.md (one row per case) and the overlays
docs/results/calibration-karlsruhe/checks_q.png and checks_epsv.png.
"""
import argparse
import csv
import os
import sys

from study_runs import completed, elastic_nu, run_cases, summary, write_table  # noqa: E402 (tools/, beside this script)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRESET = os.path.join(ROOT, "presets", "karlsruhe-calibrated.toml")
CASES = [
    ("p100", "dense, p = 100 kPa", ["test.confining_pressure=100.0e3"]),
    ("p200", "dense, p = 200 kPa (calibration)", ["test.confining_pressure=200.0e3"]),
    ("p400", "dense, p = 400 kPa", ["test.confining_pressure=400.0e3"]),
    ("loose", "loose e0 = 0.80, p = 200 kPa", ["sample.e0=0.80", "sample.prep_friction_deg=\"auto\""]),
    ("cell", "periodic cell, e0 = 0.53, p = 200 kPa",
     ['test.boundary="periodic"', "sample.prep_friction_deg=\"auto\""]),
]
COMMON = ["output.plots=false", "output.vtk_every_strain=0"]
# Wu (1992) via [W]: dense Karlsruhe sand, e0 = 0.53, p = 200 kPa.
LAB = {"phi_peak_deg": 43.7, "psi_max_deg": 28.5, "E50_MPa": 104.0}


def run(a):
    return run_cases(a.exe, PRESET, [(os.path.join(a.runs, c), COMMON + sets) for c, _, sets in CASES], a.jobs)


def series(folder):
    with open(os.path.join(folder, "timeseries.csv")) as f:
        rows = list(csv.DictReader(f))
    col = lambda k: [float(r[k]) for r in rows]  # noqa: E731
    return col("eps1"), col("q"), col("eps_v"), col("p"), col("e")


def fmt(v, digits=1):
    return "null" if v is None else f"{v:.{digits}f}"


def report(a):
    out_dir = os.path.join(a.docs, "calibration-karlsruhe")
    os.makedirs(out_dir, exist_ok=True)
    lines = ["| case | e0 | Z | φp [°] | ε1 at peak [%] | ψmax [°] | φres [°] | E50 [MPa] | E0 [MPa] | ν0 | "
             "εv at 20 % [%] | q/p end | e end | σ3 dev. max [%] | wall [s] |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    fig_q, ax_q = plt.subplots(figsize=(7, 4.5))
    fig_v, ax_v = plt.subplots(figsize=(7, 4.5))
    for case, label, _ in CASES:
        folder = os.path.join(a.runs, case)
        if not completed(folder):
            lines.append(f"| {label} | not run | | | | | | | | | | | | | |")
            continue
        s = summary(folder)
        eps1, q, epsv, p, e = series(folder)
        end = [i for i, x in enumerate(eps1) if x >= 0.16]
        qp_end = sum(q[i] / p[i] for i in end) / len(end) if end else None
        e_end = sum(e[i] for i in end) / len(end) if end else None
        dev = s.get("lateral_stress_max_deviation")
        lines.append(
            f"| {label} | {s['e0']:.3f} | {s['Z']:.2f} | {fmt(s.get('phi_peak_deg'))} | "
            f"{fmt(100 * s['eps1_at_peak'] if s.get('eps1_at_peak') is not None else None)} | "
            f"{fmt(s.get('psi_max_deg'))} | {fmt(s.get('phi_res_deg'))} | {fmt(s.get('E50_MPa'), 0)} | "
            f"{fmt(s.get('E0_MPa'), 0)} | {fmt(elastic_nu(s.get('nu0')), 2)} | {100 * epsv[-1]:.2f} | {fmt(qp_end, 2)} | "
            f"{fmt(e_end, 3)} | {fmt(100 * dev if dev is not None else None)} | {s['wall_seconds']:.0f} |")
        pc = s["confining_pressure"]
        ax_q.plot([100 * x for x in eps1], [y / pc for y in q], label=label)
        ax_v.plot([100 * x for x in eps1], [100 * y for y in epsv], label=label)
    ax_q.set_xlabel("axial strain ε1 [%]")
    ax_q.set_ylabel("q / σ3")
    ax_q.set_title("Karlsruhe-calibrated sand: deviator stress")
    ax_v.set_xlabel("axial strain ε1 [%]")
    ax_v.set_ylabel("volumetric strain εv [%] (contraction > 0)")
    ax_v.set_title("Karlsruhe-calibrated sand: volume change")
    for fig, ax, name in ((fig_q, ax_q, "checks_q.png"), (fig_v, ax_v, "checks_epsv.png")):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, name), dpi=100)
    write_table(os.path.join(a.docs, "calibration-karlsruhe-checks.md"), lines,
                header="<!-- written by tools/karlsruhe_checks.py report -->\n")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=["run", "report"])
    ap.add_argument("--runs", default=os.path.join(ROOT, "runs", "karlsruhe-checks"))
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "grainlab"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    return run(a) if a.what == "run" else report(a)


if __name__ == "__main__":
    sys.exit(main())
