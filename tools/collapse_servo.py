#!/usr/bin/env python3
"""Lateral stress in column collapses: the cases of the [W] one-at-a-time study whose lateral stress
left the 2 % band (docs/results/w-parameter-studies.md), sheared twice from the same prepared sample,
with the test's servo cap at the preparation's 0.5 m/s and at the default 2 m/s.

    /usr/bin/python3 tools/collapse_servo.py [--runs runs/collapse-servo] [--exe build/grainlab] [--jobs 2]
        [--out docs/results/collapse-servo-table.md]

Each run takes 3-6 minutes on one thread; completed runs are skipped, so an interrupted call resumes.
The preparation does not depend on test.servo_max_speed, so both runs of a case shear the same sample
and agree up to the first collapse that reaches the cap.
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import run_cases, summary, write_table  # noqa: E402

CASES = [  # (name, label, the --set that makes the case)
    ("mu40", "μ = 40°", "contact.friction_deg=40"),
    ("p300", "p = 300 kPa", "test.confining_pressure=300e3"),
    ("beta0.1", "β = 0.1", "contact.beta=0.1"),
    ("mu35", "μ = 35°", "contact.friction_deg=35"),
]
CAPS = [("cap0.5", 0.5), ("cap2", 2.0)]


def collapses(folder):
    """Recording intervals after 0.2 % axial strain in which q fell below 85 % of the previous one."""
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return sum(1 for a, b in zip(rows, rows[1:])
               if float(a["eps1"]) > 0.002 and float(b["q"]) < 0.85 * float(a["q"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", default="runs/collapse-servo")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default="docs/results/collapse-servo-table.md")
    a = ap.parse_args()
    cases = [(os.path.join(a.runs, f"{name}-{tag}"), [s, f"test.servo_max_speed={cap}"])
             for name, _, s in CASES for tag, cap in CAPS]
    run_cases(a.exe, "preset:w-base", cases, a.jobs)
    lines = ["| case | e0 | test.servo_max_speed [m/s] | σ3 dev. max [%] | single wall [%] | collapses | "
             "φp [°] | ψmax [°] | φres [°] | wall [s] |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, label, _ in CASES:
        for tag, cap in CAPS:
            folder = os.path.join(a.runs, f"{name}-{tag}")
            s = summary(folder)
            lines.append(f"| {label} | {s['e0']:.4f} | {cap:g} | {100 * s['lateral_stress_max_deviation']:.2f} | "
                         f"{100 * s['lateral_stress_max_deviation_single_wall']:.2f} | {collapses(folder)} | "
                         f"{s['phi_peak_deg']:.2f} | {s['psi_max_deg']:.2f} | {s['phi_res_deg']:.2f} | "
                         f"{s['wall_seconds']:.0f} |")
    write_table(a.out, lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
