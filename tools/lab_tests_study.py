#!/usr/bin/env python3
"""The laboratory tests of issue 24 on the calibrated Karlsruhe sand (presets csl-dense and
csl-loose: 2000 spheres, periodic cell, 200 kPa), with replicate seeds: undrained triaxial of a
loose and a dense sample (and of the [W] law's base sample, preset w-base, for comparison), the
oedometer, cyclic triaxial at several CSRs, cyclic simple shear drained and undrained
(docs/results/lab-tests.md).

    /usr/bin/python3 tools/lab_tests_study.py run    [--runs runs/lab-tests] [--exe build/grainlab] [--jobs 2]
                                                     [--seeds 1,2,3] [--only cu,cu-slow,oedometer,cyclic,css,ucss,cav,ucss-loose,cu-w,cu-w-cav]
    /usr/bin/python3 tools/lab_tests_study.py report [--runs runs/lab-tests] [--seeds 1,2,3]
                                                     [--out docs/results/lab-tests.md]

`run` runs every case whose folder is not completed (1 thread each, --jobs at a time; an interrupted
`run` resumes where it stopped). `report` reads the summaries and time series, writes the tables
(docs/results/lab-tests/*.md) and plots (docs/results/lab-tests/*.png) and prints what it read;
a case that did not complete is listed as missing, never filled in.
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

# Cases: (group, preset, name, sets). Rates: the reversing tests' "auto" is a hundredth of the
# monotonic rate (minutes per run at 2000 spheres); 0.1 1/s keeps the inertial number ~6e-5.
CU = ['test.drainage="undrained"', "test.final_axial_strain=0.2"]
OEDOMETER = ['test.type="oedometer"', "test.max_axial_stress=2e6", "test.unload_axial_stress=200e3",
             "test.axial_strain_rate=0.1", "output.vtk_every_strain=0"]
CYCLIC = ['test.type="cyclic-triaxial"', 'test.drainage="undrained"', "test.n_cycles=15",
          "test.axial_strain_rate=0.1", "output.vtk_every_strain=0"]
# The loose undrained test again with the loading rate following p' (test.rate_follows_pressure),
# beside the same samples at the fixed rate: is the flow's minimum p' a rate effect?
CU_SLOW = CU + ["test.rate_follows_pressure=true"]
CSRS = (0.10, 0.15, 0.20, 0.25)
# The dense undrained test again with cavitation of the pore water (test.back_pressure 300 kPa: it
# cavitates at u = -399 kPa), beside the ideal constraint of "cu" (u falls to about -14 p0).
CAV = CU + ["test.back_pressure=300e3"]
CSS = ['test.type="cyclic-simple-shear"', "test.shear_strain_amplitudes=[1e-5, 1e-4, 1e-3, 1e-2]",
       "test.cycles_per_amplitude=2", "output.vtk_every_strain=0"]


def cases(seeds, only):
    for seed in seeds:
        s = [f"sample.seed={seed}"]
        if "cu" in only:
            yield "cu", "csl-loose", f"cu-loose_s{seed}", CU + s
            yield "cu", "csl-dense", f"cu-dense_s{seed}", CU + s
        if "cu-slow" in only:
            if "cu" not in only:
                yield "cu-slow", "csl-loose", f"cu-loose_s{seed}", CU + s
            yield "cu-slow", "csl-loose", f"cu-loose-slow_s{seed}", CU_SLOW + s
        if "oedometer" in only:
            yield "oedometer", "csl-dense", f"oed-dense_s{seed}", OEDOMETER + s
        if "cyclic" in only:
            for csr in CSRS:
                yield "cyclic", "csl-loose", f"cyc-loose_csr{csr:g}_s{seed}", CYCLIC + [f"test.csr={csr}"] + s
        if "css" in only:
            yield "css", "csl-dense", f"css-dense_s{seed}", CSS + s
        if "cav" in only:
            yield "cav", "csl-dense", f"cu-dense-bp300_s{seed}", CAV + s
        if "ucss" in only:
            yield "ucss", "csl-dense", f"ucss-dense_s{seed}", CSS + ['test.drainage="undrained"'] + s
        if "ucss-loose" in only:
            yield "ucss-loose", "csl-loose", f"ucss-loose_s{seed}", CSS + ['test.drainage="undrained"'] + s
        if "cu-w" in only:
            yield "cu-w", "w-base", f"cu-w_s{seed}", CU + ["output.vtk_every_strain=0"] + s
        if "cu-w-cav" in only:
            yield "cu-w-cav", "w-base", f"cu-w-bp300_s{seed}", CAV + ["output.vtk_every_strain=0"] + s


def run(a):
    for preset in ("csl-loose", "csl-dense", "w-base"):
        todo = [(os.path.join(a.runs, name), sets) for g, p, name, sets in cases(a.seeds, a.only) if p == preset]
        run_cases(a.exe, f"preset:{preset}", todo, a.jobs)
    return 0


def series(folder):
    with open(os.path.join(folder, "timeseries.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) if r[k] != "" else math.nan for r in rows] for k in rows[0]}


def fmt(v, digits=3):
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int,)) and not isinstance(v, bool):
        return str(v)
    return f"{v:.{digits}g}"


def mean_sd(values):
    v = [x for x in values if x is not None]
    if not v:
        return "null"
    if len(v) == 1:
        return f"{v[0]:.3g} (1 seed)"
    return f"{statistics.mean(v):.3g} ± {statistics.stdev(v):.2g} ({len(v)} seeds)"


def runs_of(done, group):
    """(preset, summary, series) of each completed run of one group, in the order of their names."""
    return [(preset, s, d) for name, (g, preset, s, d) in sorted(done.items()) if g == group]


def cu_report(done, group, title, png, table):
    """The table and the q-p' / u-eps1 plot of one undrained triaxial group."""
    lines = ["| sample | seed | e0 | p′ min [kPa] | u max [kPa] | q at PT [kPa] | ε1 at PT [%] | liquefied | "
             "p′ end [kPa] | q end [kPa] | φ mobilised end [°] | volume drift max | wall [s] |",
             "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|"]
    fig, (ax, axu) = plt.subplots(1, 2, figsize=(11, 4.2))
    for preset, s, d in runs_of(done, group):
        pt_q, pt_e = s.get("q_at_phase_transformation"), s.get("eps1_at_phase_transformation")
        sample = preset.split("-")[1]
        p_end, q_end = d["p"][-1], d["q"][-1]
        # Mobilised friction at the end from q/p' in compression: sin phi = 3 eta / (6 + eta).
        eta = q_end / p_end if p_end > 0 else None
        phi_end = math.degrees(math.asin(3 * eta / (6 + eta))) if eta is not None else None
        lines.append(f"| {sample} | {s['seed']} | {s['e0']:.3f} | {s['p_min'] / 1e3:.1f} | "
                     f"{s['u_max'] / 1e3:.1f} | {fmt(pt_q / 1e3 if pt_q is not None else None)} | "
                     f"{fmt(100 * pt_e if pt_e is not None else None)} | {fmt(s['liquefied'])} | "
                     f"{p_end / 1e3:.0f} | {q_end / 1e3:.0f} | {fmt(phi_end)} | {s['volume_drift_max']:.1e} | "
                     f"{s['wall_seconds']:.0f} |")
        colour = "tab:red" if "loose" in preset else ("tab:blue" if group == "cu" else f"C{s['seed'] - 1}")
        ax.plot([p / 1e3 for p in d["p"]], [q / 1e3 for q in d["q"]], color=colour, lw=0.9,
                label=f"{sample} s{s['seed']}")
        axu.plot([100 * e for e in d["eps1"]], [u / s["confining_pressure"] for u in d["u"]], color=colour, lw=0.9)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("p′ [kPa] (log)")
    ax.set_ylabel("q [kPa] (log)")
    ax.legend(fontsize=7)
    axu.set_xlabel("axial strain ε1 [%]")
    axu.set_ylabel("u / p0")
    axu.set_yscale("symlog", linthresh=1.0)
    for x in (ax, axu):
        x.grid(alpha=0.3, which="both")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    write_table(table, lines)


def ru_at(d, s, k):
    """The largest recorded ru = u/p0 while amplitude k was cycled (the `amplitude` column is k + 1)."""
    return max(u for u, a in zip(d["u"], d["amplitude"]) if a == k + 1) / s["confining_pressure"]


def cav_report(done, group, title, png, table):
    """The table and the q-p' / eps_v plot of one undrained group with cavitation (test.back_pressure)."""
    lines = ["| seed | e0 | u_cav [kPa] | ε1 at cavitation [%] | u min [kPa] | q peak [kPa] | ε1 at peak [%] | "
             "φ peak [°] | p′ end [kPa] | q end [kPa] | εv end [%] | volume drift max (undrained part) | wall [s] |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    fig, (ax, axv) = plt.subplots(1, 2, figsize=(11, 4.2))
    for preset, s, d in runs_of(done, group):
        ce = s["cavitation_strain"]
        lines.append(f"| {s['seed']} | {s['e0']:.3f} | {s['cavitation_pressure'] / 1e3:.1f} | "
                     f"{fmt(100 * ce if ce is not None else None)} | {s['u_min'] / 1e3:.1f} | "
                     f"{s['q_peak'] / 1e3:.0f} | {100 * s['eps1_at_peak']:.1f} | {s['phi_peak_deg']:.1f} | "
                     f"{d['p'][-1] / 1e3:.0f} | {d['q'][-1] / 1e3:.0f} | {100 * d['eps_v'][-1]:.1f} | "
                     f"{s['volume_drift_max']:.1e} | {s['wall_seconds']:.0f} |")
        ax.plot([p / 1e3 for p in d["p"]], [q / 1e3 for q in d["q"]], lw=0.9, label=f"seed {s['seed']}")
        axv.plot([100 * e for e in d["eps1"]], [100 * v for v in d["eps_v"]], lw=0.9, label=f"seed {s['seed']}")
    ax.set_xlabel("p′ [kPa]")
    ax.set_ylabel("q [kPa]")
    axv.set_xlabel("axial strain ε1 [%]")
    axv.set_ylabel("εv [%] (compression positive)")
    for x in (ax, axv):
        x.grid(alpha=0.3)
        x.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    write_table(table, lines)


def css_report(done, group, title, png, table):
    """The G/Gmax and damping table and plot of one cyclic simple shear group."""
    per_amp = {}
    undrained = group.startswith("ucss")
    lines = ["| seed | e0 | Gmax [MPa] | E0/(2(1+ν0)) [MPa] | G/Gmax at γa | ξ [%] at γa | "
             + ("ru max at γa | σzz max [kPa] | σzz end [kPa] | volume drift max | " if undrained else "") + "wall [s] |",
             "|---:|---:|---:|---:|---|---|" + ("---|---:|---:|---:|" if undrained else "") + "---:|"]
    fig, (axg, axd) = plt.subplots(1, 2, figsize=(11, 4.2))
    for preset, s, d in runs_of(done, group):
        amps, ratio, xi = s["shear_strain_amplitudes"], s["G_over_Gmax"], s["damping_ratio"]
        for k, (am, r, x) in enumerate(zip(amps, ratio, xi)):
            per_amp.setdefault(k, []).append((am, r, x))
        gp = s["E0_MPa"] / (2 * (1 + s["nu0"])) if s.get("E0_MPa") and s.get("nu0") is not None else None
        lines.append(f"| {s['seed']} | {s['e0']:.3f} | {fmt(s['Gmax_MPa'])} | {fmt(gp)} | "
                     + ", ".join(f"{r:.3f} @ {am:.0e}" for am, r in zip(amps, ratio)) + " | "
                     + ", ".join(f"{100 * x:.2f}" for x in xi) + " | "
                 + (", ".join(f"{ru_at(d, s, k):.3f}" for k in range(len(amps))) + " | "
                    f"{max(d['sigma1']) / 1e3:.0f} | {d['sigma1'][-1] / 1e3:.0f} | {s['volume_drift_max']:.1e} | "
                    if undrained else "") + f"{s['wall_seconds']:.0f} |")
        axg.semilogx(amps, ratio, "o-", lw=0.9, label=f"seed {s['seed']}")
        axd.semilogx(amps, [100 * x for x in xi], "s-", lw=0.9, label=f"seed {s['seed']}")
    axg.set_xlabel("shear strain amplitude γa")
    axg.set_ylabel("G / Gmax")
    axd.set_xlabel("shear strain amplitude γa")
    axd.set_ylabel("damping ratio ξ [%]")
    for x in (axg, axd):
        x.grid(alpha=0.3, which="both")
        x.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    lines.append("")
    lines.append("| γa | G/Gmax | ξ [%] |")
    lines.append("|---:|---|---|")
    for k in sorted(per_amp):
        v = per_amp[k]
        lines.append(f"| {statistics.mean(x[0] for x in v):.1e} | {mean_sd([x[1] for x in v])} | "
                     f"{mean_sd([100 * x[2] for x in v])} |")
    write_table(table, lines)


def report(a):
    out_dir = os.path.splitext(a.out)[0]
    os.makedirs(out_dir, exist_ok=True)
    done, missing = {}, []
    for g, preset, name, sets in cases(a.seeds, a.only):
        f = os.path.join(a.runs, name)
        if completed(f):
            done[name] = (g, preset, dict(summary(f), seed=int(name.rsplit('_s', 1)[1])), series(f))
        else:
            missing.append(name)
    lines = []
    # Undrained triaxial: the calibrated sand, and the [W] law's base sample for comparison.
    if "cu" in a.only:
        cu_report(done, "cu", "Undrained triaxial, calibrated Karlsruhe sand, p0 = 200 kPa (red loose, blue dense)",
                  os.path.join(out_dir, "undrained.png"), os.path.join(out_dir, "undrained-table.md"))
    if "cu-w-cav" in a.only:
        cav_report(done, "cu-w-cav", "Undrained triaxial, [W] set (w-base), p0 = 100 kPa, back pressure 300 kPa "
                   "(cavitation at u = −399 kPa)",
                   os.path.join(out_dir, "undrained-w-cav.png"), os.path.join(out_dir, "undrained-w-cav-table.md"))
    if "cu-w" in a.only:
        cu_report(done, "cu-w", "Undrained triaxial, the [W] law's base sample (w-base, e0 = 0.60), p0 = 100 kPa",
                  os.path.join(out_dir, "undrained-w.png"), os.path.join(out_dir, "undrained-w-table.md"))
    # Undrained loose: fixed rate against the rate that follows p'.
    if "cu-slow" in a.only:
        lines = ["| rate | seed | e0 | p′ min [kPa] | ε1 at p′ min [%] | liquefied | I max | rate factor min | "
                 "q at 5 % [kPa] | p′ end [kPa] | q end [kPa] | volume drift max | wall [s] |",
                 "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
        fig, (ax, axp) = plt.subplots(1, 2, figsize=(11, 4.2))
        for seed in a.seeds:
            for name, label, style in ((f"cu-loose_s{seed}", "fixed (from p0)", "-"),
                                       (f"cu-loose-slow_s{seed}", "follows p′", "--")):
                if name not in done:
                    continue
                g, preset, s, d = done[name]
                eps, p, q = d["eps1"], d["p"], d["q"]
                k = min(range(len(p)), key=lambda i: p[i])
                q5 = next((q[i] for i in range(len(eps)) if eps[i] >= 0.05), None)
                lines.append(f"| {label} | {seed} | {s['e0']:.3f} | {s['p_min'] / 1e3:.1f} | {100 * eps[k]:.2f} | "
                             f"{fmt(s['liquefied'])} | {s['inertial_number_max']:.2g} | {fmt(s.get('rate_factor_min'))} | "
                             f"{fmt(q5 / 1e3 if q5 is not None else None)} | {p[-1] / 1e3:.0f} | {q[-1] / 1e3:.0f} | "
                             f"{s['volume_drift_max']:.1e} | {s['wall_seconds']:.0f} |")
                colour = f"C{seed - 1}"
                ax.plot([x / 1e3 for x in p], [x / 1e3 for x in q], style, color=colour, lw=0.9,
                        label=f"seed {seed}, {label}")
                axp.plot([100 * e for e in eps], [x / 1e3 for x in p], style, color=colour, lw=0.9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("p′ [kPa] (log)")
        ax.set_ylabel("q [kPa] (log)")
        ax.legend(fontsize=7)
        axp.set_xlabel("axial strain ε1 [%]")
        axp.set_ylabel("p′ [kPa] (log)")
        axp.set_yscale("log")
        for x in (ax, axp):
            x.grid(alpha=0.3, which="both")
        fig.suptitle("Undrained triaxial, loose calibrated Karlsruhe sand, p0 = 200 kPa: fixed rate (solid) "
                     "and rate following p′ (dashed)", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "undrained-rate.png"), dpi=110)
        plt.close(fig)
        write_table(os.path.join(out_dir, "undrained-rate-table.md"), lines)
    # Oedometer.
    if "oedometer" in a.only:
        lines = ["| seed | e0 | K0 | K0 unloading | Cc | Cs | σv max [kPa] | wall [s] |", "|---:|---:|---:|---:|---:|---:|---:|---:|"]
        k0s, fig = [], plt.figure(figsize=(5.5, 4.2))
        for preset, s, d in runs_of(done, "oedometer"):
            k0s.append(s["K0"])
            lines.append(f"| {s['seed']} | {s['e0']:.3f} | {fmt(s['K0'])} | {fmt(s['K0_unloading'])} | {fmt(s['Cc'])} | "
                         f"{fmt(s['Cs'])} | {s['sigma_v_max'] / 1e3:.0f} | {s['wall_seconds']:.0f} |")
            plt.semilogx([v / 1e3 for v in d["sigma1"]], d["e"], lw=0.9, label=f"seed {s['seed']}")
        plt.xlabel("σv [kPa] (log)")
        plt.ylabel("void ratio e")
        plt.grid(alpha=0.3, which="both")
        plt.legend(fontsize=8)
        plt.title("Oedometer, dense, from 200 kPa isotropic", fontsize=10)
        plt.tight_layout()
        plt.savefig(os.path.join(out_dir, "oedometer.png"), dpi=110)
        plt.close()
        lines.append("")
        lines.append(f"K0 on loading over the seeds: {mean_sd(k0s)}")
        write_table(os.path.join(out_dir, "oedometer-table.md"), lines)
    # Cyclic triaxial.
    if "cyclic" in a.only:
        lines = ["| CSR | seed | e0 | N to liquefaction | ru max | DA strain max [%] | cycles run | volume drift max | wall [s] |",
                 "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        fig = plt.figure(figsize=(5.5, 4.2))
        cyclic = sorted(runs_of(done, "cyclic"), key=lambda r: (r[1]["csr"], r[1]["seed"]))
        for preset, s, d in cyclic:
            n = s["n_cycles_to_liquefaction"]
            lines.append(f"| {s['csr']:g} | {s['seed']} | {s['e0']:.3f} | {fmt(n)} | {fmt(s['ru_max'])} | "
                         f"{100 * s['double_amplitude_strain_max']:.2f} | {s['cycles']:g} | {s['volume_drift_max']:.1e} | "
                         f"{s['wall_seconds']:.0f} |")
            if n is not None:
                plt.semilogx([n], [s["csr"]], "o", color="tab:red")
            else:
                plt.semilogx([s["cycles"]], [s["csr"]], ">", color="tab:grey")
        # Per CSR over the seeds: N of each seed (a run that did not liquefy counts as "> cycles run").
        lines += ["", "| CSR | seeds | liquefied | N per seed | N median |", "|---:|---:|---:|---|---:|"]
        by_csr = {}
        for preset, s, d in cyclic:
            by_csr.setdefault(s["csr"], []).append(s)
        medians = []
        for csr in sorted(by_csr):
            v = sorted(by_csr[csr], key=lambda s: s["seed"])
            ns = [s["n_cycles_to_liquefaction"] for s in v]
            shown = [fmt(n) if n is not None else f"> {s['cycles']:g}" for n, s in zip(ns, v)]
            # A run that did not liquefy is censored: N > cycles run. The median is still known when
            # the middle value(s) of the sorted Ns are not censored (censored ones sort last).
            ordered = sorted(math.inf if n is None else n for n in ns)
            mid = ordered[(len(ordered) - 1) // 2: len(ordered) // 2 + 1]
            median = statistics.mean(mid) if all(math.isfinite(x) for x in mid) else None
            if median is not None:
                medians.append((csr, median))
            shown_median = fmt(median) if median is not None else "> " + f"{min(s['cycles'] for s in v):g}"
            lines.append(f"| {csr:g} | {len(v)} | {sum(n is not None for n in ns)} | {', '.join(shown)} | {shown_median} |")
            if median is not None:
                plt.semilogx([median], [csr], "_", ms=18, mew=2, color="black")
        # CSR = a N^-b through the medians (least squares in log-log): the exponent a laboratory
        # campaign reports (clean sands: b ~ 0.2-0.35).
        if len(medians) >= 3:
            x = [math.log(n) for _, n in medians]
            y = [math.log(c) for c, _ in medians]
            mx, my = statistics.mean(x), statistics.mean(y)
            b = -sum((xi - mx) * (yi - my) for xi, yi in zip(x, y)) / sum((xi - mx) ** 2 for xi in x)
            lines += ["", f"CSR = a·N^(−b) through the {len(medians)} medians (least squares in log–log): b = {b:.2f}"]
            plt.semilogx([n for _, n in medians], [c for c, _ in medians], "-", color="black", lw=0.8,
                         label=f"median over the seeds (b = {b:.2f})")
            plt.legend(fontsize=8)
        plt.xlabel("cycles to liquefaction N (▶ grey: not liquefied; bar: median)", fontsize=9)
        plt.ylabel("CSR = q_cyc / (2 p0)")
        plt.grid(alpha=0.3, which="both")
        plt.title("Undrained cyclic triaxial, loose (e0 ≈ 0.65), p0 = 200 kPa, 3 seeds", fontsize=10)
        plt.tight_layout()
        plt.savefig(os.path.join(out_dir, "csr-n.png"), dpi=110)
        plt.close()
        write_table(os.path.join(out_dir, "cyclic-table.md"), lines)
    # Undrained with cavitation (test.back_pressure): the dense calibrated sand, and the [W] set.
    if "cav" in a.only:
        cav_report(done, "cav", "Undrained triaxial, dense, p0 = 200 kPa, back pressure 300 kPa (cavitation at u = −399 kPa)",
                   os.path.join(out_dir, "cavitation.png"), os.path.join(out_dir, "cavitation-table.md"))
    # Cyclic simple shear, drained and undrained.
    for group, title, png, table in (("css", "Drained cyclic simple shear, dense, σzz = 200 kPa", "css.png", "css-table.md"),
                                     ("ucss", "Undrained (constant-volume) cyclic simple shear, dense, p0 = 200 kPa",
                                      "ucss.png", "ucss-table.md"),
                                     ("ucss-loose", "Undrained (constant-volume) cyclic simple shear, loose, p0 = 200 kPa",
                                      "ucss-loose.png", "ucss-loose-table.md")):
        if group in a.only:
            css_report(done, group, title, os.path.join(out_dir, png), os.path.join(out_dir, table))
    # A group none of whose cases completed has no table or plot (not an empty one).
    files = {"cu": ("undrained-table.md", "undrained.png"), "cu-slow": ("undrained-rate-table.md", "undrained-rate.png"), "oedometer": ("oedometer-table.md", "oedometer.png"),
             "cyclic": ("cyclic-table.md", "csr-n.png"), "css": ("css-table.md", "css.png"),
             "ucss": ("ucss-table.md", "ucss.png"), "cav": ("cavitation-table.md", "cavitation.png"),
             "ucss-loose": ("ucss-loose-table.md", "ucss-loose.png"), "cu-w": ("undrained-w-table.md", "undrained-w.png"),
             "cu-w-cav": ("undrained-w-cav-table.md", "undrained-w-cav.png")}
    # Only the groups asked for (--only): a report of some campaigns leaves the others' files alone.
    ran = {g for g, _, _, _ in done.values()}
    for g, names in files.items():
        if g in a.only and g not in ran:
            for n in names:
                if os.path.exists(os.path.join(out_dir, n)):
                    os.remove(os.path.join(out_dir, n))
    print("missing:", ", ".join(missing) if missing else "none")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=("run", "report"))
    ap.add_argument("--runs", default="runs/lab-tests")
    ap.add_argument("--exe", default="build/grainlab")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--only", default="cu,cu-slow,oedometer,cyclic,css,ucss,cav,ucss-loose,cu-w,cu-w-cav")
    ap.add_argument("--out", default="docs/results/lab-tests.md")
    a = ap.parse_args()
    a.seeds = [int(s) for s in a.seeds.split(",")]
    a.only = set(a.only.split(","))
    return run(a) if a.command == "run" else report(a)


if __name__ == "__main__":
    sys.exit(main())
