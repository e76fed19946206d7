#!/usr/bin/python3
"""Shear bands in the membrane and in rigid walls (docs/results/shear-bands.md).

    /usr/bin/python3 tools/shear_bands.py run [--seeds 1 2] [--walls-seeds 1]   # the runs, into runs/shear-bands
    /usr/bin/python3 tools/shear_bands.py report                                # the page and its figures

`run` runs presets/membrane-triaxial.toml (the membrane) and examples/shear-bands/walls.toml (the same
sample in six rigid walls) for each seed, one at a time on two threads, skipping runs that finished.
`report` reads every finished run's summary.json and timeseries.csv and writes the table of
docs/results/shear-bands.md (between its markers) and docs/results/shear-bands-*.png."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNS = os.path.join(ROOT, "runs", "shear-bands")
PAGE = os.path.join(ROOT, "docs", "results", "shear-bands.md")
BIN = os.environ.get("GRAINLAB_BIN", os.path.join(ROOT, "build", "grainlab"))
CASES = {"membrane": os.path.join(ROOT, "presets", "membrane-triaxial.toml"),
         "walls": os.path.join(ROOT, "examples", "shear-bands", "walls.toml")}
BEGIN, END = "<!-- shear-bands table: begin -->", "<!-- shear-bands table: end -->"


def run_dir(case, seed):
    return os.path.join(RUNS, f"{case}-s{seed}")


def finished(path):
    try:
        with open(os.path.join(path, "summary.json")) as f:
            return json.load(f).get("status") == "completed"
    except (OSError, ValueError):
        return False


def run(args):
    os.makedirs(RUNS, exist_ok=True)
    todo = [("membrane", s) for s in args.seeds] + [("walls", s) for s in args.walls_seeds]
    for case, seed in todo:
        out = run_dir(case, seed)
        if finished(out):
            print(f"{case} seed {seed}: done already")
            continue
        argv = [BIN, "run", CASES[case], "--out", out, "--set", f"sample.seed={seed}", "--threads", "2", "--quiet"]
        print(" ".join(argv), flush=True)
        rc = subprocess.run(argv).returncode
        if rc != 0:
            print(f"{case} seed {seed}: exit {rc}", file=sys.stderr)


def rows(path):
    with open(os.path.join(path, "timeseries.csv")) as f:
        out = []
        for r in csv.DictReader(f):
            out.append({k: (float(v) if v not in ("", "null", "nan") else None) for k, v in r.items()})
        return out


def num(x, fmt="{:.1f}"):
    return "null" if x is None or (isinstance(x, float) and math.isnan(x)) else fmt.format(x)


def estimates(s):
    """Band inclination to the horizontal: Mohr-Coulomb 45 + phi/2, Roscoe 45 + psi/2, Arthur
    45 + (phi + psi)/4, with the peak friction angle and the largest dilatancy angle (sin form)."""
    phi, psi = s.get("phi_peak_deg"), s.get("psi_max_deg")
    if phi is None or psi is None:
        return None, None, None
    return 45 + phi / 2, 45 + psi / 2, 45 + (phi + psi) / 4


def band_history(r):
    """(eps1, detected, inclination, thickness) at every closed band window."""
    return [(x["eps1"], x["band_inclination_deg"] is not None, x["band_inclination_deg"], x["band_thickness_d50"])
            for x in r if x.get("band_measured") == 1.0]


def figures(runs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    colours = {"membrane": "tab:blue", "walls": "tab:red"}
    for (case, seed), (s, r) in sorted(runs.items()):
        e = [100 * x["eps1"] for x in r]
        lab = f"{case}, seed {seed}"
        ax[0].plot(e, [x["q"] / 1e3 for x in r], color=colours[case], lw=1, label=lab)
        ax[1].plot(e, [100 * x["eps_v"] for x in r], color=colours[case], lw=1, label=lab)
        if case == "membrane":
            ax[2].plot(e, [x["rotation_band_mean_deg"] if x["rotation_band_mean_deg"] is not None else math.nan for x in r],
                       color="tab:blue", lw=1, label=f"in the band flag (eq >= band_factor x sample's), seed {seed}")
            ax[2].plot(e, [x["rotation_outside_band_mean_deg"] if x["rotation_outside_band_mean_deg"] is not None else math.nan
                           for x in r], color="tab:green", lw=1, label=f"the other grains, seed {seed}")
    ax[0].set_ylabel("deviator q [kPa]")
    ax[1].set_ylabel("volumetric strain eps_v [%] (contraction +)")
    ax[2].set_ylabel("mean grain rotation [deg] (membrane)")
    for a in ax:
        a.set_xlabel("axial strain eps1 [%]")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("membrane-triaxial against the same sample in rigid walls (20 000 spheres, 100 kPa)")
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs", "results", "shear-bands-curves.png"), dpi=110)
    plt.close(fig)


def report(args):
    runs = {}
    if os.path.isdir(RUNS):
        for name in sorted(os.listdir(RUNS)):
            path = os.path.join(RUNS, name)
            if not finished(path) or "-s" not in name:
                continue
            case, seed = name.rsplit("-s", 1)
            with open(os.path.join(path, "summary.json")) as f:
                runs[(case, int(seed))] = (json.load(f), rows(path))
    if not runs:
        sys.exit("no finished runs in runs/shear-bands: run `tools/shear_bands.py run` first")
    lines = [BEGIN, "",
             "| run | e0 | φp [°] | ε1 at peak [%] | q_peak [kPa] | q at 20 % [kPa] | ψmax [°] | εv at 20 % [%] | "
             "band at the end | inclination [°] | MC / Roscoe / Arthur [°] | thickness [d50] | onset ε1 [%] (/ peak) | "
             "e inside / outside | steps | wall time |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for (case, seed), (s, r) in sorted(runs.items()):
        b = s.get("shear_band") or {}
        mc, roscoe, arthur = estimates(s)
        onset = b.get("onset_eps1")
        lines.append(
            f"| {case}, seed {seed} | {num(s.get('e0'), '{:.3f}')} | {num(s.get('phi_peak_deg'))} | "
            f"{num(100 * s['eps1_at_peak'] if s.get('eps1_at_peak') is not None else None)} | "
            f"{num(s.get('q_peak') / 1e3 if s.get('q_peak') else None, '{:.0f}')} | {num(r[-1]['q'] / 1e3, '{:.0f}')} | "
            f"{num(s.get('psi_max_deg'))} | {num(100 * r[-1]['eps_v'])} | "
            f"{'null' if b.get('detected') is None else ('yes' if b['detected'] else 'no')} | "
            f"{num(b.get('inclination_deg'))} | {num(mc)} / {num(roscoe)} / {num(arthur)} | {num(b.get('thickness_d50'))} | "
            f"{num(100 * onset if onset is not None else None)} ({num(b.get('onset_over_peak'), '{:.2f}')}) | "
            f"{num(b.get('void_ratio_inside'), '{:.3f}')} / {num(b.get('void_ratio_outside'), '{:.3f}')} | "
            f"{s.get('steps')} | {num(s.get('wall_seconds') / 60 if s.get('wall_seconds') else None, '{:.1f}')} min on {s['threads_used'] if 'threads_used' in s else str(s.get('threads')) + ' requested'} thread(s) |")
    lines += ["", "Band windows of each run (ε1 at the window's end: inclination / thickness in d50, or — where none "
              "was found):", ""]
    for (case, seed), (s, r) in sorted(runs.items()):
        h = band_history(r)
        cells = [f"{100 * e:.0f} %: {num(i, '{:.0f}')}° / {num(t, '{:.1f}')}" if d else f"{100 * e:.0f} %: —"
                 for e, d, i, t in h]
        lines.append(f"- {case}, seed {seed}: " + "; ".join(cells))
    lines += ["", END]
    figures(runs)
    # The last band window's strain increment through the axis of each boundary's first seed.
    import shutil
    for case in CASES:
        seeds = sorted(seed for c, seed in runs if c == case)
        if seeds:
            src = os.path.join(run_dir(case, seeds[0]), "plots", "band_slice.png")
            if os.path.exists(src):
                shutil.copyfile(src, os.path.join(ROOT, "docs", "results", f"shear-bands-slice-{case}.png"))
    with open(PAGE) as f:
        page = f.read()
    a, b = page.index(BEGIN), page.index(END) + len(END)
    with open(PAGE, "w") as f:
        f.write(page[:a] + "\n".join(lines) + page[b:])
    print(f"wrote {os.path.relpath(PAGE, ROOT)} ({len(runs)} runs)")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--seeds", type=int, nargs="+", default=[1])
    r.add_argument("--walls-seeds", type=int, nargs="*", default=[1])
    sub.add_parser("report")
    args = p.parse_args()
    run(args) if args.cmd == "run" else report(args)


if __name__ == "__main__":
    main()
