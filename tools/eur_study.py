#!/usr/bin/env python3
"""Unload-reload moduli of the calibrated sand and of the [W] law with eta = 1, with and without a rest
before the unload, and the rate dependence of the [W] samples that the rest reveals (docs/moduli.md,
"Eur: what the loops measure").

    /usr/bin/python3 tools/eur_study.py [--runs runs/eur-study] [--exe build/grainlab] [--jobs 2]
        [--out docs/results/eur-table.md]

Loops at 0.5 % and 2 % axial strain, shear to 3 %, one thread per run (each 1-5 minutes); completed
runs are skipped, so an interrupted call resumes.
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import positive_modulus, run_cases, summary, write_table  # noqa: E402

LOOPS = ["test.unload_reload_at=[0.005,0.02]", "test.final_axial_strain=0.03"]
AUTO_RATE_W = 1.1923383855050151  # the auto rate of w-base (I = 0.98e-3), from its summary.json
CASES = [  # (folder, preset, label, sets)
    ("ks", "karlsruhe-calibrated", "karlsruhe-calibrated, unload to 0.5 q", LOOPS),
    ("ks-0.9", "karlsruhe-calibrated", "karlsruhe-calibrated, unload to 0.9 q", LOOPS + ["test.unload_to_q_fraction=0.9"]),
    ("ks-rest", "karlsruhe-calibrated", "karlsruhe-calibrated, rest, unload to 0.5 q", LOOPS + ["test.loop_rest=true"]),
    ("wb", "w-base", "w-base, unload to 0.5 q", LOOPS),
    ("wb-0.9", "w-base", "w-base, unload to 0.9 q", LOOPS + ["test.unload_to_q_fraction=0.9"]),
    ("wb-rest", "w-base", "w-base, rest, unload to 0.5 q", LOOPS + ["test.loop_rest=true"]),
    ("wb-rest-0.9", "w-base", "w-base, rest, unload to 0.9 q",
     LOOPS + ["test.loop_rest=true", "test.unload_to_q_fraction=0.9"]),
]
RATES = [("rate-1", 1), ("rate-2", 2), ("rate-4", 4)]  # w-base to 3 % at the auto rate / k, no loop


def q_at(folder, eps):
    """q [kPa] of the monotonic records at axial strain eps (linear interpolation)."""
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r.get("loop_phase", "0") == "0"]
    for a, b in zip(rows, rows[1:]):
        ea, eb = float(a["eps1"]), float(b["eps1"])
        if ea <= eps <= eb and eb > ea:
            return (float(a["q"]) + (eps - ea) / (eb - ea) * (float(b["q"]) - float(a["q"]))) / 1e3
    return None


def fmt(v, spec):
    return "–" if v is None else format(v, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", default="runs/eur-study")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default="docs/results/eur-table.md")
    a = ap.parse_args()
    for preset in ("karlsruhe-calibrated", "w-base"):
        cases = [(os.path.join(a.runs, name), sets) for name, p, _, sets in CASES if p == preset]
        run_cases(a.exe, f"preset:{preset}", cases, a.jobs)
    run_cases(a.exe, "preset:w-base",
              [(os.path.join(a.runs, name), [f"test.axial_strain_rate={AUTO_RATE_W / k!r}", "test.final_axial_strain=0.03"])
               for name, k in RATES], a.jobs)
    lines = ["| case | E0 [MPa] | E50 [MPa] | q relaxed in the rest [%] | Eur 0.5 % [MPa] | Eur 2 % [MPa] | Eur/E0 (0.5 %) |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, _, label, _ in CASES:
        s = summary(os.path.join(a.runs, name))
        eur = [positive_modulus(v) for v in s["Eur_MPa"]]
        relax = [fmt(100 * r if r is not None else None, ".1f") for r in s.get("Eur_rest_q_relaxation") or [None, None]]
        lines.append(f"| {label} | {s['E0_MPa']:.0f} | {s['E50_MPa']:.0f} | {' / '.join(relax)} | {fmt(eur[0], '.0f')} | "
                     f"{fmt(eur[1], '.0f')} | {fmt(eur[0] / s['E0_MPa'] if eur[0] is not None else None, '.2f')} |")
    lines += ["", "| w-base to 3 %, rate | strain rate [1/s] | I max | steps | q at 0.5 % [kPa] | q at 1 % [kPa] | "
              "φp to 3 % [°] | E50 [MPa] |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for name, k in RATES:
        folder = os.path.join(a.runs, name)
        s = summary(folder)
        lines.append(f"| auto / {k} | {s['strain_rate']:.3f} | {s['inertial_number_max']:.2e} | {s['steps']} | "
                     f"{fmt(q_at(folder, 0.005), '.0f')} | {fmt(q_at(folder, 0.01), '.0f')} | {s['phi_peak_deg']:.1f} | "
                     f"{s['E50_MPa']:.0f} |")
    write_table(a.out, lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
