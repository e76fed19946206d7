#!/usr/bin/env python3
"""The parameter studies of Widulinski et al. (2009) on the `w-base` preset, run and published.

    /usr/bin/python3 tools/w_studies.py run    [--runs DIR] [--exe build/grainlab] [--jobs 2]
    /usr/bin/python3 tools/w_studies.py report [--runs DIR] [--docs docs/results]
    /usr/bin/python3 tools/w_studies.py size   [--size-runs runs/w-size] [--sizes 2000,8000]
    /usr/bin/python3 tools/w_studies.py compare --runs DIR_A --runs-b DIR_B [--out FILE]
    /usr/bin/python3 tools/w_studies.py replicates [--seeds 3] [--runs runs/w-studies-seeds] [--set K=V]

`run` shears the base case once (2 threads), then one `grainlab sweep` per study over the values
that differ from the base (1 thread per case, --jobs cases at a time); a study whose sweep.csv
already lists all its cases as completed is skipped, so an interrupted `run` picks up where it
stopped. `report` writes docs/results/w-parameter-studies-table.md (one row per case, base
included in every study) and overlay plots docs/results/w-studies/<study>_q.png and _epsv.png.
`size` runs the base case alone on 2 threads at each number of spheres (skipping those done) and
writes docs/results/w-size-table.md and docs/results/w-studies/size_q.png, size_epsv.png.
`replicates` runs every case (base included) with --seeds N replicate samples (default 3; one
`grainlab sweep --seeds` per study, cases already completed are kept) into --runs (default
runs/w-studies-seeds) and writes docs/results/w-parameter-studies-seeds-table.md: mean ± standard
deviation over the seeds of each case, [W]'s published base-case values beside the base, and for
every non-base case whether its difference from the base exceeds twice the larger of the two
standard deviations (a trend) or not. --set KEY=VALUE applies to every case (e.g. a smoke test
with few grains).
`compare` puts two complete runs of the studies (e.g. two code versions or seeds) side by side,
case by case, with the mean absolute difference of each quantity: the scatter of a single run.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import elastic_nu, residual_state  # noqa: E402 (tools/, beside this script)

# (study, key, values, base value, label, how a value is printed)
BASE = {"contact.beta": 0.15, "contact.eta": 1.0, "contact.friction_deg": 30.0,
        "contact.young": 30e9, "test.confining_pressure": 100e3, "sample.e0": 0.60}
STUDIES = [
    # "densest": frictionless compaction (prep_friction_deg = 0), the densest state of this grading
    # in a box; [W]'s e0 = 0.50 is below it for spheres against rigid walls.
    ("e0", "sample.e0", ["densest", 0.60, 0.70, 0.80, 0.90], "e0 target"),
    ("beta", "contact.beta", [0, 0.10, 0.15, 1, 3, 50], "β"),
    ("eta", "contact.eta", [0.1, 0.15, 1, 3], "η"),
    ("mu", "contact.friction_deg", [20, 30, 35, 40], "μ [°]"),
    ("Ec", "contact.young", [3e9, 30e9], "Ec [GPa]"),
    ("p", "test.confining_pressure", [100e3, 300e3], "p [kPa]"),
]


def shown(value):
    """A summary number to one decimal, or "null" where it was not measured."""
    return "null" if value is None else f"{value:.1f}"


def nu_text(summary):
    """nu of the summary for the table: null outside [0, 0.5] (study_runs.elastic_nu)."""
    nu = elastic_nu(summary.get("nu"))
    return "null" if nu is None else f"{nu:.2f}"


def show(key, value):
    if value == "densest":
        return "densest"
    if key == "contact.young":
        return f"{value / 1e9:g}"
    if key == "test.confining_pressure":
        return f"{value / 1e3:g}"
    return f"{value:g}"


def is_base(key, value):
    return value != "densest" and abs(float(value) - BASE[key]) <= 1e-9 * max(1.0, abs(BASE[key]))


def sh(args):
    print("+", " ".join(args), flush=True)
    return subprocess.run(args).returncode


def completed(directory, n):
    path = os.path.join(directory, "sweep.csv")
    if not os.path.exists(path):
        return False
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return len(rows) == n and all(r["status"] == "completed" for r in rows)


def run(opt):
    t0 = time.time()
    base = os.path.join(opt.runs, "base")
    if not os.path.exists(os.path.join(base, "summary.json")):
        sh([opt.exe, "run", "preset:w-base", "--out", base, "--threads", "2", "--quiet"])
    for study, key, values, _ in STUDIES:
        others = [v for v in values if not is_base(key, v)]
        out = os.path.join(opt.runs, study)
        numeric = [v for v in others if v != "densest"]
        if numeric and not completed(out, len(numeric)):
            sh([opt.exe, "sweep", "preset:w-base", "--vary", f"{key}=" + ",".join(f"{v:g}" for v in numeric),
                "--jobs", str(opt.jobs), "--threads", "1", "--quiet", "--out", out])
        if "densest" in others:
            dense = os.path.join(opt.runs, "e0-densest")
            if not completed(dense, 1):
                sh([opt.exe, "sweep", "preset:w-base", "--vary", "sample.prep_friction_deg=0",
                    "--jobs", "1", "--threads", "2", "--quiet", "--out", dense])
    print(f"studies done in {time.time() - t0:.0f} s", flush=True)


def cases_of(opt, study, key, values):
    """(value, case directory) for every value of a study, base included, in the study's order."""
    found = {}
    sources = [os.path.join(opt.runs, study)]
    if study == "e0":
        sources.append(os.path.join(opt.runs, "e0-densest"))
    for source in sources:
        path = os.path.join(source, "sweep.csv")
        if not os.path.exists(path):
            continue
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                if r["status"] != "completed":
                    continue
                if "sample.prep_friction_deg" in r:
                    found["densest"] = os.path.join(source, r["case"])
                else:
                    found[float(r[key])] = os.path.join(source, r["case"])
    out = []
    for v in values:
        if is_base(key, v):
            out.append((v, os.path.join(opt.runs, "base")))
        elif v == "densest" and "densest" in found:
            out.append((v, found["densest"]))
        elif v != "densest":
            match = [d for k, d in found.items() if k != "densest" and abs(k - float(v)) <= 1e-9 * max(1, abs(v))]
            out.append((v, match[0] if match else None))
        else:
            out.append((v, None))
    return out


def load(directory):
    if directory is None or not os.path.exists(os.path.join(directory, "summary.json")):
        return None, None
    with open(os.path.join(directory, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(directory, "timeseries.csv"), newline="") as f:
        series = list(csv.DictReader(f))
    return summary, series


def finish_overlays(figs, title, plots, stem):
    """Labels, legend and atomic PNG save of a q-eps1 / eps_v-eps1 figure pair."""
    for column, (fig, ax) in figs.items():
        ax.set_xlabel("axial strain ε1 [%]")
        ax.set_ylabel("deviator stress q [kPa]" if column == "q" else "volumetric strain εv [%] (contraction +)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        target = os.path.join(plots, f"{stem}_{'q' if column == 'q' else 'epsv'}.png")
        fig.savefig(target + ".tmp.png", dpi=100)
        os.replace(target + ".tmp.png", target)
        plt.close(fig)


def write_table(path, lines):
    """Writes a markdown table atomically and prints it."""
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(path + ".tmp", path)
    print("\n".join(lines))


def report(opt):
    plots = os.path.join(opt.docs, "w-studies")
    os.makedirs(plots, exist_ok=True)
    lines = ["| study | value | e0 reached | φp [°] | ε1 at peak [%] | φres [°] | ψmax [°] | E [MPa] | "
             "E50 [MPa] | ν | q/p res | e res | I max | σ3 dev. max [%] | wall [s] |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    total_wall = 0.0
    seen = set()
    for study, key, values, label in STUDIES:
        figs = {c: plt.subplots(figsize=(7, 4.5)) for c in ("q", "eps_v")}
        for value, directory in cases_of(opt, study, key, values):
            summary, series = load(directory)
            name = show(key, value) + (" (base)" if is_base(key, value) else "")
            if summary is None:
                lines.append(f"| {study} | {name} | not run or failed |" + " |" * 12)
                continue
            if directory not in seen:
                total_wall += summary["wall_seconds"]
                seen.add(directory)
            lines.append(
                f"| {study} | {name} | {summary['e0']:.3f} | {summary['phi_peak_deg']:.1f} | "
                f"{100 * summary['eps1_at_peak']:.2f} | {summary['phi_res_deg']:.1f} | {summary['psi_max_deg']:.1f} | "
                f"{summary['E_MPa']:.0f} | {summary['E50_MPa']:.0f} | {nu_text(summary)} | "
                f"{residual_state(summary)[0]:.2f} | {residual_state(summary)[1]:.3f} | "
                f"{summary['inertial_number_max']:.2e} | {100 * summary['lateral_stress_max_deviation']:.1f} | "
                f"{summary['wall_seconds']:.0f} |")
            eps1 = [100 * float(r["eps1"]) for r in series]
            legend = f"{label} = {show(key, value)}" + (f" (e0 {summary['e0']:.3f})" if study == "e0" else "")
            figs["q"][1].plot(eps1, [float(r["q"]) / 1e3 for r in series], lw=1.1, label=legend)
            figs["eps_v"][1].plot(eps1, [100 * float(r["eps_v"]) for r in series], lw=1.1, label=legend)
        finish_overlays(figs, f"[W] study: {label} (others at the base case)", plots, study)
    lines.append("")
    lines.append(f"Sum of the distinct cases' wall times: {total_wall:.0f} s ({total_wall / 60:.1f} min of runs; "
                 "cases ran two at a time on one thread each, the base case alone on two threads).")
    write_table(os.path.join(opt.docs, "w-parameter-studies-table.md"), lines)


def size(opt):
    sizes = [int(n) for n in opt.sizes.split(",")]
    rows = ["| spheres | e0 reached | φp [°] | ε1 at peak [%] | φres [°] | ψmax [°] | E [MPa] | q/p res | e res | "
            "σ3 dev. max [%] | rotation in / outside band [°] | wall [s] |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    figs = {c: plt.subplots(figsize=(7, 4.5)) for c in ("q", "eps_v")}
    for n in sizes:
        out = os.path.join(opt.size_runs, f"n{n}")
        if not os.path.exists(os.path.join(out, "summary.json")):
            sh([opt.exe, "run", "preset:w-base", "--set", f"sample.n_particles={n}", "--out", out, "--threads", "2",
                "--quiet"])
        summary, series = load(out)
        if summary is None:
            rows.append(f"| {n} | failed |" + " |" * 10)
            continue
        rows.append(f"| {n} | {summary['e0']:.3f} | {summary['phi_peak_deg']:.1f} | {100 * summary['eps1_at_peak']:.2f} | "
                    f"{summary['phi_res_deg']:.1f} | {summary['psi_max_deg']:.1f} | {summary['E_MPa']:.0f} | "
                    f"{residual_state(summary)[0]:.2f} | {residual_state(summary)[1]:.3f} | "
                    f"{100 * summary['lateral_stress_max_deviation']:.1f} | "
                    f"{shown(summary['rotation_band_mean_deg'])} / {shown(summary['rotation_outside_band_mean_deg'])} | "
                    f"{summary['wall_seconds']:.0f} |")
        eps1 = [100 * float(r["eps1"]) for r in series]
        legend = f"{n} spheres (e0 {summary['e0']:.3f})"
        figs["q"][1].plot(eps1, [float(r["q"]) / 1e3 for r in series], lw=1.1, label=legend)
        figs["eps_v"][1].plot(eps1, [100 * float(r["eps_v"]) for r in series], lw=1.1, label=legend)
    plots = os.path.join(opt.docs, "w-studies")
    os.makedirs(plots, exist_ok=True)
    finish_overlays(figs, "[W] base case: number of spheres", plots, "size")
    write_table(os.path.join(opt.docs, "w-size-table.md"), rows)


def compare(opt):
    keys = [("e0", "e0", 3, 1), ("φp", "phi_peak_deg", 1, 1), ("φres", "phi_res_deg", 1, 1),
            ("ψmax", "psi_max_deg", 1, 1), ("E", "E_MPa", 0, 1), ("σ3 dev. %", "lateral_stress_max_deviation", 1, 100),
            ("wall s", "wall_seconds", 0, 1)]
    head = "| study | value | " + " | ".join(f"{k[0]} A / B" for k in keys) + " |"
    lines = [head, "|---|---|" + "---:|" * len(keys)]
    diffs = {k[1]: [] for k in keys}
    seen = set()
    for study, key, values, _ in STUDIES:
        a_cases = cases_of(argparse.Namespace(runs=opt.runs), study, key, values)
        b_cases = cases_of(argparse.Namespace(runs=opt.runs_b), study, key, values)
        for (value, da), (_, db) in zip(a_cases, b_cases):
            sa, _ = load(da)
            sb, _ = load(db)
            name = show(key, value) + (" (base)" if is_base(key, value) else "")
            if sa is None or sb is None:
                lines.append(f"| {study} | {name} | missing |" + " |" * (len(keys) - 1))
                continue
            cells = []
            for _, k, digits, scale in keys:
                cells.append(f"{scale * sa[k]:.{digits}f} / {scale * sb[k]:.{digits}f}")
                if (da, db) not in seen:
                    diffs[k].append(abs(scale * (sa[k] - sb[k])))
            seen.add((da, db))
            lines.append(f"| {study} | {name} | " + " | ".join(cells) + " |")
    lines.append("| mean abs. difference | | " + " | ".join(
        f"{sum(diffs[k[1]]) / max(1, len(diffs[k[1]])):.{max(k[2], 1)}f}" for k in keys) + " |")
    write_table(opt.out, lines)


# [W]'s values for the base case as its text states them (quoted by the project's review, issue 23);
# the other cases' published values are not at hand as numbers.
W_BASE = {"phi_peak_deg": 40.0, "phi_res_deg": 29.0, "psi_max_deg": 16.0, "E_MPa": 95.0}
REPLICATE_COLUMNS = [("e0", "e0", 3), ("φp [°]", "phi_peak_deg", 1), ("φres [°]", "phi_res_deg", 1),
                     ("ψmax sin [°]", "psi_max_deg", 1), ("ψmax tan [°]", "psi_max_tan_deg", 1),
                     ("E0 [MPa]", "E_MPa", 0), ("E50 [MPa]", "E50_MPa", 0), ("e end", "end_void_ratio", 3)]


def replicate_cases(opt):
    """(study, key, value, label, folder of the sweep, row-selector) for every case, base first."""
    out = [("base", None, None, "base", os.path.join(opt.runs, "base"), lambda r: True)]
    for study, key, values, _ in STUDIES:
        for v in values:
            if is_base(key, v):
                continue
            if v == "densest":
                out.append((study, key, v, "densest", os.path.join(opt.runs, "e0-densest"), lambda r: True))
            else:
                out.append((study, key, v, show(key, v), os.path.join(opt.runs, study),
                            lambda r, key=key, v=v: abs(float(r[key]) - float(v)) <= 1e-9 * max(1.0, abs(float(v)))))
    return out


def replicates(opt):
    sets = [a for s in opt.set for a in ("--set", s)]
    common = ["--seeds", str(opt.seeds), "--jobs", str(opt.jobs), "--threads", "1", "--quiet", *sets]
    sh([opt.exe, "sweep", "preset:w-base", *common, "--out", os.path.join(opt.runs, "base")])
    for study, key, values, _ in STUDIES:
        numeric = [v for v in values if v != "densest" and not is_base(key, v)]
        if numeric:
            sh([opt.exe, "sweep", "preset:w-base", "--vary", f"{key}=" + ",".join(f"{v:g}" for v in numeric), *common,
                "--out", os.path.join(opt.runs, study)])
        if "densest" in values:
            sh([opt.exe, "sweep", "preset:w-base", "--vary", "sample.prep_friction_deg=0", *common,
                "--out", os.path.join(opt.runs, "e0-densest")])
    replicates_report(opt)


def stats_rows(folder, select):
    path = os.path.join(folder, "sweep-stats.csv")
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if select(r)]
    return rows[0] if rows else None


def replicates_report(opt):
    def cell(row, k, digits):
        n = int(row[k + "_n"]) if row.get(k + "_n") else 0
        if n == 0:
            return "null"
        mean = float(row[k + "_mean"])
        if n >= 3:
            return f"{mean:.{digits}f} ± {float(row[k + '_std']):.{digits}f}"
        if n == 2:
            return f"[{float(row[k + '_min']):.{digits}f}, {float(row[k + '_max']):.{digits}f}]"
        return f"{mean:.{digits}f}"

    lines = ["| study | value | seeds | " + " | ".join(c[0] for c in REPLICATE_COLUMNS) +
             " | critical state | trend against the base (> 2 std) |",
             "|---|---|---:|" + "---:|" * len(REPLICATE_COLUMNS) + "---|---|"]
    base = stats_rows(os.path.join(opt.runs, "base"), lambda r: True)
    for study, key, value, label, folder, select in replicate_cases(opt):
        row = stats_rows(folder, select)
        if row is None:
            lines.append(f"| {study} | {label} | not run |" + " |" * (len(REPLICATE_COLUMNS) + 2))
            continue
        cells = [cell(row, k, d) for _, k, d in REPLICATE_COLUMNS]
        reached = row.get("critical_state_reached_mean")
        n = int(row.get("critical_state_reached_n") or 0)
        cs = f"{round(float(reached) * n)} of {n}" if reached else "null"
        trends, compared = [], 0
        if study != "base" and base is not None:
            for name, k, digits in REPLICATE_COLUMNS[1:5]:
                # A standard deviation needs two seeds on both sides; otherwise nothing is claimed.
                if not row.get(k + "_std") or not base.get(k + "_std"):
                    continue
                compared += 1
                d = float(row[k + "_mean"]) - float(base[k + "_mean"])
                bound = 2 * max(float(row[k + "_std"]), float(base[k + "_std"]))
                if abs(d) > bound:
                    trends.append(f"{name.rsplit(' [', 1)[0]} {d:+.{digits}f}")
            trend = (", ".join(trends) if trends else "none beyond the scatter") if compared else "not measurable"
        else:
            trend = "–"
        lines.append(f"| {study} | {label} | {row['seeds_completed']} of {row['seeds']} | " + " | ".join(cells) +
                     f" | {cs} | {trend} |")
        if study == "base":
            lines.append("| [W] (2009) | base | – | 0.60 | " + " | ".join(
                f"{W_BASE[k]:g}" if k in W_BASE else "–" for _, k, _ in REPLICATE_COLUMNS[1:]) + " | – | – |")
    header = (f"Over {opt.seeds} seeds per case (runs in {opt.runs}): mean ± sample standard deviation (the range "
              "for 2 seeds); a trend is a difference from the base beyond twice the larger standard deviation. "
              "[W]'s E is its modulus E0/σc label's, set beside our E0.\n\n")
    os.makedirs(opt.docs, exist_ok=True)
    out = os.path.join(opt.docs, "w-parameter-studies-seeds-table.md")
    with open(out + ".tmp", "w") as f:
        f.write(header + "\n".join(lines) + "\n")
    os.replace(out + ".tmp", out)
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("action", choices=["run", "report", "size", "compare", "replicates", "replicates-report"])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE for every case (replicates)")
    ap.add_argument("--runs-b", default="runs/w-studies-v2")
    ap.add_argument("--out", default="docs/results/w-parameter-studies-compare.md")
    ap.add_argument("--size-runs", default="runs/w-size")
    ap.add_argument("--sizes", default="2000,8000")
    ap.add_argument("--runs", default="runs/w-studies")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--docs", default="docs/results")
    opt = ap.parse_args()
    if opt.action == "size":
        size(opt)
        return 0
    if opt.action == "compare":
        compare(opt)
        return 0
    if opt.action in ("replicates", "replicates-report"):
        if opt.runs == "runs/w-studies":
            opt.runs = "runs/w-studies-seeds"
        replicates(opt) if opt.action == "replicates" else replicates_report(opt)
        return 0
    if opt.action == "run":
        run(opt)
    report(opt)
    return 0


if __name__ == "__main__":
    sys.exit(main())
