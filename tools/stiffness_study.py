#!/usr/bin/env python3
"""Stiffness that follows pressure (issue 27 §3): E0, Gmax, E50 and Eur of the [W] x10 sand at
25-800 kPa with the linear contacts of [W] and with Hertz-Mindlin (quartz), replicate seeds, the
exponent n of E ∝ p^n with its uncertainty, and Hardin and Richart's Gmax beside them.

    /usr/bin/python3 tools/stiffness_study.py run [--runs runs/stiffness] [--exe build/grainlab]
        [--jobs 2] [--laws linear,hertz-mindlin] [--seeds 1,2,3]
    /usr/bin/python3 tools/stiffness_study.py report [--runs runs/stiffness] [--docs docs/results]

Every run: preset quick-triaxial (1000 spheres of the [W] x10 grading, 2-8 mm, densest state by
frictionless compaction to the test's pressure, the moments of [W]: beta 0.15, eta 1, mu 30 deg,
smooth rigid walls), the small-strain probe (E0, nu0) after consolidation, then drained
compression at the auto rate (inertial number 1e-3) to 3 % axial strain with one unload-reload
loop at 0.5 % (to half the deviator). Hertz-Mindlin: contact.shear_modulus 29 GPa, poisson 0.2,
the [W] moments in the rolling slot. One thread per run; completed runs are skipped.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_runs import completed, elastic_nu, positive_modulus, run_cases, summary  # noqa: E402

PRESSURES_KPA = [25, 50, 100, 200, 400, 800]
COMMON = ["test.final_axial_strain=0.03", "test.unload_reload_at=[0.005]", 'test.axial_strain_rate="auto"',
          "output.plots=false", "output.vtk_every_strain=0", "output.checkpoint_every=0"]
LAWS = {
    "linear": ("linear contacts of [W] (Ec 30 GPa, nu_c 0.3)", []),
    "hertz-mindlin": ("Hertz-Mindlin, quartz (G 29 GPa, nu 0.2)",
                      ['contact.model="hertz-mindlin"', "contact.shear_modulus=29e9", "contact.poisson=0.2",
                       'contact.rolling="kozicki"']),
}


def folder(runs, law, p, seed):
    return os.path.join(runs, law, f"p{p}kPa-seed{seed}")


def cases(runs, laws, seeds):
    out = []
    for law in laws:
        sets = LAWS[law][1]
        for p in PRESSURES_KPA:
            for seed in seeds:
                out.append((folder(runs, law, p, seed),
                            COMMON + sets + [f"test.confining_pressure={p * 1e3!r}", f"sample.seed={seed}"]))
    return out


def unloading_secant(run_dir):
    """[MPa] the secant of the first loop's unloading branch, from the reversal (the last record
    before loop_phase 1) to the lowest deviator of the unloading (the end of phase 1): dq / d eps1.
    The summary's Eur is the reload branch's secant (docs/laboratory.md); the two differ where the
    loop is open. None without a loop in the time series, or where the branch is too short."""
    import csv
    path = os.path.join(run_dir, "timeseries.csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows or "loop_phase" not in rows[0]:
        return None
    phases = [r["loop_phase"] for r in rows]
    if "1" not in phases:
        return None
    start = phases.index("1") - 1
    end = start + 1
    while end + 1 < len(rows) and phases[end + 1] == "1":
        end += 1
    if start < 0:
        return None
    de = float(rows[start]["eps1"]) - float(rows[end]["eps1"])
    dq = float(rows[start]["q"]) - float(rows[end]["q"])
    # A branch whose strain change is under 1e-5 is mostly the deviator relaxing at the reversal
    # (the platen stops, q falls at almost constant strain): no modulus (null), not a huge one.
    return positive_modulus(dq / de / 1e6) if de > 1e-5 else None


def measures(s, run_dir=None):
    """The moduli of one run's summary (None where not measured)."""
    e0 = positive_modulus(s.get("E0_MPa"))
    nu0 = elastic_nu(s.get("nu0"))
    eur = s.get("Eur_MPa") or [None]
    eur = positive_modulus(eur[0])
    e50 = positive_modulus(s.get("E50_MPa"))
    return {"e0": s.get("e0"), "Z": s.get("Z"), "Z_mech": s.get("Z_mech"), "E0": e0, "nu0": nu0,
            "Gmax": e0 / (2.0 * (1.0 + nu0)) if e0 is not None and nu0 is not None else None,
            "E50": e50, "Eur": eur, "Eur/E50": eur / e50 if eur and e50 else None,
            "Eunl": (eunl := unloading_secant(run_dir) if run_dir else None),
            "Eunl/E50": eunl / e50 if eunl and e50 else None,
            "phi_p": s.get("phi_peak_deg"), "steps": s.get("steps"), "wall": s.get("wall_seconds")}


def hardin_gmax_mpa(e, p_kpa):
    """Hardin and Richart (1963), round-grained (Ottawa) sand: G = 6908 (2.17 - e)^2 / (1 + e) p^0.5,
    G and p in kPa (their 2630 in psi units, converted)."""
    return 6908.0 * (2.17 - e) ** 2 / (1.0 + e) * math.sqrt(p_kpa) / 1e3


def fit_exponent(points):
    """Least squares of log M = log A + n log p over every (p, M) of every seed: n and its standard
    error (None with fewer than 3 points)."""
    pts = [(p, m) for p, m in points if m is not None and m > 0]
    if len(pts) < 3:
        return None, None
    x = np.log([p for p, _ in pts])
    y = np.log([m for _, m in pts])
    A = np.column_stack([np.ones_like(x), x])
    coef, res, *_ = np.linalg.lstsq(A, y, rcond=None)
    dof = len(pts) - 2
    sigma2 = float(np.sum((y - A @ coef) ** 2)) / dof if dof > 0 else float("nan")
    cov = sigma2 * np.linalg.inv(A.T @ A)
    return float(coef[1]), float(math.sqrt(cov[1, 1]))


def stats(values):
    v = [x for x in values if x is not None]
    if not v:
        return None, None, 0
    return float(np.mean(v)), (float(np.std(v, ddof=1)) if len(v) > 1 else None), len(v)


def fmt(mean, std, spec):
    if mean is None:
        return "null"
    return f"{mean:{spec}}" + (f" ± {std:{spec}}" if std is not None else "")


def collect(runs, laws, seeds):
    data = {}
    for law in laws:
        for p in PRESSURES_KPA:
            rows = []
            for seed in seeds:
                d = folder(runs, law, p, seed)
                if completed(d):
                    rows.append(dict(measures(summary(d), d), seed=seed))
            data[(law, p)] = rows
    return data


def report(runs, docs, laws, seeds):
    data = collect(runs, laws, seeds)
    lines = ["| law | p [kPa] | seeds | e0 | Z | E0 [MPa] | ν0 | Gmax [MPa] | Hardin Gmax [MPa] | E50 [MPa] | "
             "Eur [MPa] | Eur/E50 | E_unl [MPa] | E_unl/E50 | φp [°] |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    fits = {}
    for law in laws:
        for p in PRESSURES_KPA:
            rows = data[(law, p)]
            col = {k: stats([r[k] for r in rows]) for k in ("e0", "Z", "E0", "nu0", "Gmax", "E50", "Eur", "Eur/E50", "Eunl", "Eunl/E50",
                                                         "phi_p")}
            hardin = stats([hardin_gmax_mpa(r["e0"], p) for r in rows if r["e0"] is not None])
            lines.append(f"| {law} | {p} | {len(rows)} | {fmt(*col['e0'][:2], '.3f')} | {fmt(*col['Z'][:2], '.2f')} | "
                         f"{fmt(*col['E0'][:2], '.0f')} | {fmt(*col['nu0'][:2], '.3f')} | {fmt(*col['Gmax'][:2], '.0f')} | "
                         f"{fmt(*hardin[:2], '.0f')} | {fmt(*col['E50'][:2], '.0f')} | {fmt(*col['Eur'][:2], '.0f')} | "
                         f"{fmt(*col['Eur/E50'][:2], '.2f')} | {fmt(*col['Eunl'][:2], '.0f')} | "
                         f"{fmt(*col['Eunl/E50'][:2], '.2f')} | {fmt(*col['phi_p'][:2], '.1f')} |")
        for key in ("E0", "Gmax", "E50", "Eur", "Eunl"):
            fits[(law, key)] = fit_exponent([(p, r[key]) for p in PRESSURES_KPA for r in data[(law, p)]])
    lines += ["", "| law | n of E0 | n of Gmax | n of E50 | n of Eur | n of E_unl |", "|---|---:|---:|---:|---:|---:|"]
    for law in laws:
        cells = []
        for key in ("E0", "Gmax", "E50", "Eur", "Eunl"):
            n, se = fits[(law, key)]
            cells.append("null" if n is None else f"{n:.3f} ± {se:.3f}")
        lines.append(f"| {law} | " + " | ".join(cells) + " |")
    os.makedirs(docs, exist_ok=True)
    with open(os.path.join(docs, "stiffness-table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    with open(os.path.join(docs, "stiffness-data.json"), "w") as f:
        json.dump({f"{law}/{p}": rows for (law, p), rows in data.items()}, f, indent=1)
    plot(data, fits, laws, os.path.join(docs, "stiffness"))


def plot(data, fits, laws, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out, exist_ok=True)
    colours = {"linear": "tab:blue", "hertz-mindlin": "tab:red"}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    for ax, key, title in ((axes[0], "E0", "small-strain Young's modulus E0 (probe)"),
                           (axes[1], "Gmax", "Gmax = E0 / 2(1 + ν0)"), (axes[2], "E50", "secant E50")):
        for law in laws:
            ps = [p for p in PRESSURES_KPA for r in data[(law, p)] if r[key] is not None]
            ms = [r[key] for p in PRESSURES_KPA for r in data[(law, p)] if r[key] is not None]
            ax.loglog(ps, ms, "o", color=colours[law], ms=4, alpha=0.6)
            n, se = fits[(law, key)]
            if n is not None:
                x = np.array([PRESSURES_KPA[0], PRESSURES_KPA[-1]], dtype=float)
                a = np.exp(np.mean(np.log(ms)) - n * np.mean(np.log(ps)))
                ax.loglog(x, a * x ** n, "-", color=colours[law], label=f"{law}: n = {n:.2f} ± {se:.2f}")
        if key == "Gmax":
            es = [r["e0"] for law in laws for p in PRESSURES_KPA for r in data[(law, p)] if law == "hertz-mindlin"]
            e = float(np.mean(es)) if es else 0.6
            x = np.geomspace(PRESSURES_KPA[0], PRESSURES_KPA[-1], 20)
            ax.loglog(x, [hardin_gmax_mpa(e, p) for p in x], "k--", lw=1,
                      label=f"Hardin & Richart (1963), e = {e:.2f}: n = 0.5")
        ax.set_xlabel("confining pressure p [kPa]")
        ax.set_ylabel(f"{key} [MPa]")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "moduli-pressure.png"), dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for law in laws:
        for key, marker, what in (("Eur/E50", "o", "Eur (reload secant)"), ("Eunl/E50", "^", "E_unl (unloading secant)")):
            ps = [p for p in PRESSURES_KPA for r in data[(law, p)] if r[key] is not None]
            ms = [r[key] for p in PRESSURES_KPA for r in data[(law, p)] if r[key] is not None]
            ax.semilogx(ps, ms, marker, color=colours[law], label=f"{law}: {what}", alpha=0.7,
                        mfc="none" if marker == "^" else None)
    ax.axhline(3.0, color="k", ls="--", lw=1, label="laboratory sands, typical (≈ 3)")
    ax.set_xlabel("confining pressure p [kPa]")
    ax.set_ylabel("modulus of the loop / E50 [-] (loop at 0.5 %)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "eur-over-e50.png"), dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("action", choices=["run", "report"])
    ap.add_argument("--runs", default="runs/stiffness")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--laws", default="linear,hertz-mindlin")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--docs", default="docs/results")
    ap.add_argument("--nice", action="store_true")
    a = ap.parse_args()
    laws = a.laws.split(",")
    for law in laws:
        if law not in LAWS:
            ap.error(f"--laws: {law!r} is not one of {', '.join(LAWS)}")
    seeds = [int(s) for s in a.seeds.split(",")]
    if a.action == "run":
        return run_cases(a.exe, "preset:quick-triaxial", cases(a.runs, laws, seeds), a.jobs, nice=a.nice)
    report(a.runs, a.docs, laws, seeds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
