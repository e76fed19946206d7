#!/usr/bin/env python3
"""The critical state of the calibrated Karlsruhe sand: dense and loose samples sheared far in the
periodic cell (presets csl-dense and csl-loose), at several pressures and seeds, and the critical
state line e = Gamma - lambda ln(p / 1 kPa) with its scatter (docs/results/critical-state.md).

    /usr/bin/python3 tools/csl_study.py run    [--runs runs/csl] [--exe build/grainlab] [--jobs 2]
                                               [--pressures 100,200,400] [--seeds 1,2,3]
    /usr/bin/python3 tools/csl_study.py report [--runs runs/csl] [--pressures ...] [--seeds ...]
                                               [--out docs/results/critical-state.md]

`run` runs every (preset, pressure, seed) whose folder is not completed (1 thread per run, --jobs
at a time; an interrupted `run` resumes). `report` reads the summaries and time series and writes
the page's tables and the plots in docs/results/critical-state/. Nothing is fitted to a run that
did not reach the criterion unless the page says so: the CSL is fitted twice, to the runs that met
the criterion and to every run's end state, and both fits are shown with the number of runs.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import completed, run_cases, summary, write_table  # noqa: E402 (tools/, beside this script)

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PRESETS = ("csl-dense", "csl-loose")
LOOSE_FALLBACK_E0 = 0.63


def folder(runs, preset, p_kpa, seed):
    return os.path.join(runs, f"{preset}_p{p_kpa:g}_s{seed}")


def cases(a):
    for preset in PRESETS:
        for p in a.pressures:
            for seed in a.seeds:
                yield preset, p, seed, folder(a.runs, preset, p, seed)


def run(a):
    todo = [(f, [f"test.confining_pressure={p * 1e3!r}", f"sample.seed={seed}"]) for preset, p, seed, f in cases(a)]
    # run_cases takes one preset; run each preset's cases in turn (both at --jobs at a time).
    for preset in PRESETS:
        run_cases(a.exe, f"preset:{preset}", [c for c in todo if os.path.basename(c[0]).startswith(preset + "_")],
                  a.jobs)
    # A loose sample whose e0 = 0.65 this seed's preparation cannot reach at the higher pressures
    # (exit 2, "looser than this preparation reaches") is run at LOOSE_FALLBACK_E0 instead; the
    # table shows the e0 each run reached.
    retry = []
    for f, sets in todo:
        if os.path.basename(f).startswith("csl-loose_") and not completed(f) and os.path.exists(f + ".log"):
            with open(f + ".log") as log:
                if "looser than this preparation reaches" in log.read():
                    retry.append((f, sets + [f"sample.e0={LOOSE_FALLBACK_E0!r}"]))
    if retry:
        run_cases(a.exe, "preset:csl-loose", retry, a.jobs)
    return 0


def read_series(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) if r[k] != "" else np.nan for r in rows]) for k in rows[0]}


def invariants(d):
    """Principal stresses of the cell's stress (sigma1 = zz, sigma2 = xx, sigma3 = yy, tau = -xz; the
    other shear components are held at zero), and from them the mobilised friction angle
    asin((s_I - s_III)/(s_I + s_III)) and the Lode parameter b = (s_II - s_III)/(s_I - s_III):
    comparable between simple shear and triaxial compression, where tau/sigma_n is not."""
    zz, xx, yy = d["sigma1"], d["sigma2"], d["sigma3"]
    tau = d["tau"] if "tau" in d else np.zeros_like(zz)
    c, r = 0.5 * (zz + xx), np.sqrt((0.5 * (zz - xx)) ** 2 + tau ** 2)
    s = np.sort(np.stack([c + r, c - r, yy]), axis=0)[::-1]
    phi = np.degrees(np.arcsin((s[0] - s[2]) / (s[0] + s[2])))
    b = (s[1] - s[2]) / np.where(s[0] > s[2], s[0] - s[2], np.nan)
    return phi, b


def strain_of(d):
    return d["gamma"] if "gamma" in d else d["eps1"]


def report(a):
    docs = os.path.dirname(os.path.abspath(a.out))
    plots = os.path.join(docs, "critical-state")
    os.makedirs(plots, exist_ok=True)
    found = []
    for preset, p, seed, f in cases(a):
        if not completed(f):
            continue
        s = summary(f)
        d = read_series(os.path.join(f, "timeseries.csv"))
        x = strain_of(d)
        phi, b = invariants(d)
        window = s.get("critical_state_window") or 0.05
        start = s["critical_state_eps1"] if s.get("critical_state_reached") else x[-1] - window
        tail = x >= start
        found.append({"preset": preset, "p": p, "seed": seed, "s": s, "d": d, "x": x,
                      "phi": float(np.nanmean(phi[tail])), "b": float(np.nanmean(b[tail])),
                      "p_end": float(np.mean(d["p"][tail])), "e_end": float(np.mean(d["e"][tail])),
                      "Z_end": float(np.mean(d["Z"][tail]))})
    if not found:
        print("no completed runs in", a.runs)
        return 1
    simple = "gamma" in found[0]["d"]
    strain = "γ" if simple else "ε1"
    lines = [f"| preset | σ [kPa] | seed | e0 | reached | {strain}* | window | e (cs or end) | p [kPa] | "
             f"{'τ/σn' if simple else 'q/p'} | φ mob. [°] | b | Z | end rates d(q/p), dεv, de | wall [s] |",
             "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in found:
        s = r["s"]
        reached = bool(s.get("critical_state_reached"))
        ratio = s["cs_q_over_p"] if reached else s.get("end_q_over_p")
        rates = s.get("end_rates") or {}
        lines.append(
            f"| {r['preset']} | {r['p']:g} | {r['seed']} | {s['e0']:.3f} | {'yes' if reached else 'no'} | "
            f"{s['critical_state_eps1']:.2f} | " if reached else
            f"| {r['preset']} | {r['p']:g} | {r['seed']} | {s['e0']:.3f} | no | – | ")
        lines[-1] += (f"{s.get('critical_state_window', float('nan')):.2f} | {r['e_end']:.3f} | {r['p_end'] / 1e3:.0f} | "
                      f"{ratio:.3f} | {r['phi']:.1f} | {r['b']:.2f} | {r['Z_end']:.2f} | "
                      f"{rates.get('d_q_over_p', float('nan')):+.2f}, {rates.get('d_eps_v', float('nan')):+.3f}, "
                      f"{rates.get('d_e', float('nan')):+.3f} | {s['wall_seconds']:.0f} |")
    # Dense against loose: the same end state?
    pair_lines = ["| σ [kPa] | seed | e dense | e loose | Δe | φ dense [°] | φ loose [°] | both reached |",
                  "|---:|---:|---:|---:|---:|---:|---:|---|"]
    by = {(r["preset"], r["p"], r["seed"]): r for r in found}
    gaps = []
    for p in a.pressures:
        for seed in a.seeds:
            dn, lo = by.get(("csl-dense", p, seed)), by.get(("csl-loose", p, seed))
            if not dn or not lo:
                continue
            both = dn["s"].get("critical_state_reached") and lo["s"].get("critical_state_reached")
            gaps.append(lo["e_end"] - dn["e_end"])
            pair_lines.append(f"| {p:g} | {seed} | {dn['e_end']:.3f} | {lo['e_end']:.3f} | {gaps[-1]:+.3f} | "
                              f"{dn['phi']:.1f} | {lo['phi']:.1f} | {'yes' if both else 'no'} |")
    # The CSL per seed, over the pressures: e = Gamma - lambda ln(p / 1 kPa).
    fit_lines = ["| fitted to | runs | λ | Γ | φcs [°] | M (TC equivalent) |", "|---|---:|---:|---:|---:|---:|"]
    fits = {}
    for label, use in (("runs that met the criterion", lambda r: bool(r["s"].get("critical_state_reached"))),
                       ("every run's end state", lambda r: True)):
        chosen = [r for r in found if use(r)]
        per_seed = []
        for seed in a.seeds:
            pts = [r for r in chosen if r["seed"] == seed]
            if len({r["p"] for r in pts}) >= 2:
                lnp = np.log([r["p_end"] / 1e3 for r in pts])
                slope, icpt = np.polyfit(lnp, [r["e_end"] for r in pts], 1)
                per_seed.append((-slope, icpt))
        phis = [r["phi"] for r in chosen]
        fits[label] = chosen
        if not chosen:
            fit_lines.append(f"| {label} | 0 | null | null | null | null |")
            continue
        lam = np.array([f[0] for f in per_seed])
        gam = np.array([f[1] for f in per_seed])
        phi = np.array(phis)
        m = 6 * np.sin(np.radians(phi)) / (3 - np.sin(np.radians(phi)))

        def show(v, digits):
            if len(v) == 0:
                return "null"
            if len(v) == 1:
                return f"{v[0]:.{digits}f} (1 seed)"
            if len(v) == 2:
                return f"[{v.min():.{digits}f}, {v.max():.{digits}f}]"
            return f"{v.mean():.{digits}f} ± {v.std(ddof=1):.{digits}f}"
        fit_lines.append(f"| {label} | {len(chosen)} | {show(lam, 3)} | {show(gam, 3)} | {show(phi, 1)} | "
                         f"{show(m, 2)} |")
    header = (f"Runs in {a.runs}; λ and Γ fitted per seed over the pressures, then mean ± sample standard "
              "deviation over the seeds (the range for 2 seeds); φcs and M over the runs.\n\n")
    write_table(a.out, lines + [""] + pair_lines + [""] + fit_lines, header)
    # Plots: e against the strain, and e against ln p with the end states.
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    for r in found:
        colour = "C0" if r["preset"] == "csl-dense" else "C3"
        ax[0].plot(100 * r["x"], r["d"]["e"], color=colour, lw=0.9, alpha=0.8,
                   label=f"{r['preset']} {r['p']:g} kPa s{r['seed']}")
        marker = "o" if r["s"].get("critical_state_reached") else "x"
        ax[1].semilogx(r["p_end"] / 1e3, r["e_end"], marker, color=colour)
    ax[0].set_xlabel(f"{'shear strain γ' if simple else 'axial strain ε1'} [%]")
    ax[0].set_ylabel("void ratio e")
    ax[0].legend(fontsize=6, ncol=2)
    ax[1].set_xlabel("mean stress p at the end [kPa]")
    ax[1].set_ylabel("e at the end (o: criterion met, x: not)")
    for axis in ax:
        axis.grid(alpha=0.3)
    fig.suptitle("csl-dense (blue) and csl-loose (red)")
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "e_strain_and_csl.png"), dpi=100)
    plt.close(fig)
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=("run", "report"))
    ap.add_argument("--runs", default="runs/csl")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--pressures", default="100,200,400", help="kPa")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--out", default="docs/results/critical-state-table.md")
    a = ap.parse_args()
    a.pressures = [float(v) for v in a.pressures.split(",")]
    a.seeds = [int(v) for v in a.seeds.split(",")]
    return run(a) if a.what == "run" else report(a)


if __name__ == "__main__":
    sys.exit(main())
