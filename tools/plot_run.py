#!/usr/bin/env python3
"""Plots of one grainlab results folder: q-eps1, eps_v-eps1, phi-eps1, e-eps1, energy, and a slice of
the local shear strain through the last particle snapshot (PNG in DIR/plots).

Usage: plot_run.py DIR
Reads DIR/timeseries.csv (and DIR/summary.json for the annotations). Signs as in docs/physics.md §1:
compression positive, eps_v > 0 in contraction (dilation plots downward)."""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    """A CSV cell as a float; an empty cell is a value that could not be measured (NaN, not 0)."""
    return float(text) if text not in ("", None) else float("nan")


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [number(r[k]) for r in rows] for k in rows[0]} if rows else {}


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def main(directory):
    data = read_columns(os.path.join(directory, "timeseries.csv"))
    if len(data.get("eps1", [])) < 2:
        return 0
    summary = {}
    try:
        with open(os.path.join(directory, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        pass
    out = os.path.join(directory, "plots")
    os.makedirs(out, exist_ok=True)
    # Simple shear is plotted against gamma with tau in the first panel (eps1 is then the dilation
    # of the cell height); the file names stay those of the triaxial plots.
    shear = "gamma" in data and "tau" in data
    strain_name = "shear strain gamma [%]" if shear else "axial strain eps1 [%]"
    eps1 = [100.0 * v for v in data["gamma" if shear else "eps1"]]
    title = "e0 = {:.3f}, p = {:.0f} kPa, N = {}".format(
        summary.get("e0", float("nan")), summary.get("confining_pressure", 0) / 1e3,
        summary.get("n_particles", "?"))

    panels = [
        ("q_eps1.png", [v / 1e3 for v in data["tau"]], "shear stress tau [kPa]") if shear else
        ("q_eps1.png", [v / 1e3 for v in data["q"]], "deviator stress q [kPa]"),
        ("epsv_eps1.png", [100.0 * v for v in data["eps_v"]], "volumetric strain eps_v [%] (contraction +)"),
        ("phi_eps1.png", data["phi_deg"], "mobilised friction angle phi [deg]"),
        ("e_eps1.png", data["e"], "void ratio e"),
    ]
    for name, y, label in panels:
        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.plot(eps1, y, lw=1.4)
        ax.set_xlabel(strain_name)
        ax.set_ylabel(label)
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        if name == "phi_eps1.png" and "phi_peak_deg" in summary:
            ax.axhline(summary["phi_peak_deg"], color="C3", ls="--", lw=0.8,
                       label="phi_p = {:.1f} deg".format(summary["phi_peak_deg"]))
            ax.axhline(summary["phi_res_deg"], color="C2", ls=":", lw=0.8,
                       label="phi_res = {:.1f} deg".format(summary["phi_res_deg"]))
            ax.legend(fontsize=8)
        if name == "epsv_eps1.png":
            ax.axhline(0.0, color="k", lw=0.5)
        fig.tight_layout()
        save(fig, os.path.join(out, name))

    # One overview sheet with the four curves.
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    for ax, (name, y, label) in zip(axes.flat, panels):
        ax.plot(eps1, y, lw=1.2)
        ax.set_xlabel("gamma [%]" if shear else "eps1 [%]")
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save(fig, os.path.join(out, "overview.png"))

    # Stress-dilatancy (Rowe): the stress ratio against the dilatancy rate D = -d eps_v/d eps of the
    # monotonic curve (stress_dilatancy.csv), coloured by strain; D > 0 is dilation.
    sd_path = os.path.join(directory, "stress_dilatancy.csv")
    if os.path.exists(sd_path):
        sd = read_columns(sd_path)
        strain_key = "gamma" if "gamma" in sd else "eps1"
        if len(sd.get(strain_key, [])) >= 2:
            panels_sd = [("q_over_p", "stress ratio q/p"), ("R", "principal stress ratio R = sigma1/sigma3")]
            if strain_key == "gamma":
                panels_sd = [("tau_over_sigma_n", "stress ratio tau/sigma_n")]
            fig, axes = plt.subplots(1, len(panels_sd), figsize=(5.5 * len(panels_sd), 4.2), squeeze=False)
            for ax, (key, label) in zip(axes[0], panels_sd):
                sc = ax.scatter(sd["D"], sd[key], c=[100.0 * v for v in sd[strain_key]], s=6, cmap="viridis")
                ax.axvline(0.0, color="k", lw=0.5)
                ax.set_xlabel("dilatancy rate D = -d eps_v / d " + ("gamma" if strain_key == "gamma" else "eps1"))
                ax.set_ylabel(label)
                ax.grid(alpha=0.3)
            fig.colorbar(sc, ax=axes[0].tolist(), label=("gamma" if strain_key == "gamma" else "eps1") + " [%]")
            fig.suptitle(title + " - stress-dilatancy", fontsize=10)
            save(fig, os.path.join(out, "stress_dilatancy.png"))

    # The energy ledger of the test ([W] §4.9, Figs. 20-21): the boundaries' work against where it
    # went (stored elastic and kinetic energy, slip, rolling and damping dissipation), cumulative
    # from the start of the test, and the residual of the balance.
    terms = ("W_boundary", "E_elastic", "E_kinetic", "D_slip", "D_roll", "D_damping")
    if all(k in data for k in terms):
        start = {k: data[k][0] for k in terms}
        fig, (ax, axr) = plt.subplots(1, 2, figsize=(11, 4.2))
        ax.plot(eps1, [v - start["W_boundary"] for v in data["W_boundary"]], "k", lw=1.6, label="work of the boundaries")
        stored = [(e - start["E_elastic"]) + (k - start["E_kinetic"]) for e, k in zip(data["E_elastic"], data["E_kinetic"])]
        ax.plot(eps1, stored, lw=1.1, label="stored (elastic + kinetic)")
        for key, label in (("D_slip", "Coulomb slip"), ("D_roll", "rolling / moment plasticity"), ("D_damping", "damping")):
            ax.plot(eps1, [v - start[key] for v in data[key]], lw=1.1, label=label)
        total = [s + (a - start["D_slip"]) + (b - start["D_roll"]) + (c - start["D_damping"])
                 for s, a, b, c in zip(stored, data["D_slip"], data["D_roll"], data["D_damping"])]
        ax.plot(eps1, total, "k:", lw=1.2, label="stored + dissipated")
        ax.set_xlabel("axial strain eps1 [%]")
        ax.set_ylabel("energy since the start of the test [J]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        if "energy_residual" in data:
            axr.plot(eps1, [100.0 * v for v in data["energy_residual"]], lw=1.1)
        axr.axhline(0.0, color="k", lw=0.5)
        axr.set_xlabel("axial strain eps1 [%]")
        axr.set_ylabel("balance residual [% of the boundary work]")
        axr.grid(alpha=0.3)
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        save(fig, os.path.join(out, "energy.png"))
    laboratory_plots(data, summary, out, title)
    band_slice(directory, summary, out, title)
    rotation_plot(data, eps1, strain_name, out, title)
    return 0


def rotation_plot(data, eps1, strain_name, out, title):
    """plots/rotation.png: the mean grain rotation inside and outside the shear band against the
    strain, each with its spread (mean +- standard deviation), as [R]'s Fig. 2 plots the band's."""
    needed = ("rotation_band_mean_deg", "rotation_outside_band_mean_deg", "rotation_band_std_deg",
              "rotation_outside_band_std_deg")
    if not all(k in data for k in needed):
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(eps1, data["rotation_mean_deg"], color="0.4", lw=0.8, label="all load-bearing grains")
    for key, std, colour, label in (("rotation_band_mean_deg", "rotation_band_std_deg", "C3", "inside the band"),
                                    ("rotation_outside_band_mean_deg", "rotation_outside_band_std_deg", "C0",
                                     "outside the band")):
        mean = data[key]
        lo = [m - s for m, s in zip(mean, data[std])]
        hi = [m + s for m, s in zip(mean, data[std])]
        ax.plot(eps1, mean, color=colour, lw=1.2, label=label + " (mean +- std)")
        ax.fill_between(eps1, lo, hi, color=colour, alpha=0.15, lw=0)
    ax.set_xlabel(strain_name)
    ax.set_ylabel("grain rotation since the start [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("in the band: local eq >= band_factor x the sample's (empty where no grain is)", fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save(fig, os.path.join(out, "rotation.png"))


def band_slice(directory, summary, out, title):
    """plots/band_slice.png: the grains of the last particle snapshot within one d50 of the sample's
    mid-plane y = const, coloured by their local shear strain increment over the last band window
    (the field the band is found from; the strain since the start of shearing for snapshots without
    it), the band's grains outlined, and the trace of the band's plane (summary shear_band) where one
    was found."""
    import glob
    snapshots = sorted(glob.glob(os.path.join(directory, "vtk", "particles_*.vtu")))
    if not snapshots:
        return
    try:
        import meshio
        import numpy as np
        m = meshio.read(snapshots[-1])
    except Exception:  # noqa: BLE001 - the plot is optional; the results are complete without it
        return
    if "local_shear_strain" not in m.point_data:
        return
    x, y, z = m.points[:, 0], m.points[:, 1], m.points[:, 2]
    d50 = (summary.get("grading") or {}).get("d50") or 2.0 * float(np.median(m.point_data["radius"]))
    centre_y = 0.5 * (y.min() + y.max())
    sel = np.abs(y - centre_y) < d50
    if not sel.any():
        return
    incremental = "strain_increment" in m.point_data and "in_band_increment" in m.point_data
    eq = m.point_data["strain_increment" if incremental else "local_shear_strain"].ravel()
    band = m.point_data["in_band_increment" if incremental else "in_band"].ravel() > 0.5
    aspect = (z.max() - z.min()) / max(x.max() - x.min(), 1e-300)
    fig, ax = plt.subplots(figsize=(6.4, min(9.0, max(3.5, 4.4 * aspect + 1.4))))
    pts = ax.scatter(1e3 * x[sel], 1e3 * z[sel], c=100.0 * eq[sel], s=12, cmap="viridis")
    ax.scatter(1e3 * x[sel & band], 1e3 * z[sel & band], s=22, facecolors="none", edgecolors="r", lw=0.6,
               label="in the band (eq >= band_factor x the sample's)")
    sb = summary.get("shear_band")
    if sb and sb.get("detected", True) and sb.get("normal"):
        n, c = np.array(sb["normal"]), np.array(sb["centre"])
        # The plane n.(p - c) = 0 in the slice y = centre_y, drawn across the sample's x range.
        if abs(n[2]) > 1e-9:
            xs = np.array([x.min(), x.max()])
            zs = c[2] - (n[0] * (xs - c[0]) + n[1] * (centre_y - c[1])) / n[2]
            ax.plot(1e3 * xs, 1e3 * zs, "r--", lw=1.0,
                    label=f"band: {sb['inclination_deg']:.1f} deg, {sb['thickness_d50']:.1f} d50 thick")
        else:
            ax.axvline(1e3 * c[0], color="r", ls="--", lw=1.0, label="band: vertical")
    elif sb and sb.get("detected") is False:
        ax.set_title("no shear band found in the last strain window (shear_band.detected = false)", fontsize=9)
    else:
        ax.set_title("shear band not looked for (shear_band.detected = null)", fontsize=9)
    fig.colorbar(pts, ax=ax, shrink=0.8, label=("local shear strain increment eq\nover the last band window [%]"
                                                if incremental else "local shear strain eq since\nthe start of shearing [%]"))
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("z [mm]")
    ax.set_aspect("equal")
    ax.set_ylim(1e3 * z.min(), 1e3 * z.max())
    ax.legend(fontsize=7, loc="lower left")
    fig.suptitle(title + f"\nslice |y - y_mid| < d50, last snapshot", fontsize=9)
    fig.tight_layout()
    save(fig, os.path.join(out, "band_slice.png"))


def laboratory_plots(data, summary, out, title):
    """The undrained, oedometer and cyclic tests' own plots (docs/laboratory.md): the effective
    stress path q-p' and u against eps1 (undrained), e-log sigma_v and sigma_h against sigma_v
    (oedometer), q-p', q-eps1 and u/p0 against the cycles (cyclic triaxial)."""
    p0 = summary.get("confining_pressure") or (data["p"][0] if data.get("p") else 1.0)
    test = summary.get("test", "")
    kpa = lambda key: [v / 1e3 for v in data[key]]
    if test == "oedometer" and "load_direction" in data:
        fig, (ax, axk) = plt.subplots(1, 2, figsize=(11, 4.2))
        load = [d > 0 for d in data["load_direction"]]
        for want, label in ((True, "loading"), (False, "unloading")):
            x = [v / 1e3 for v, l in zip(data["sigma1"], load) if l == want]
            e = [v for v, l in zip(data["e"], load) if l == want]
            ax.semilogx(x, e, ".-", ms=2, lw=1, label=label)
            sh = [0.5 * (a + b) / 1e3 for a, b, l in zip(data["sigma2"], data["sigma3"], load) if l == want]
            axk.plot(x, sh, ".-", ms=2, lw=1, label=label)
        ax.set_xlabel("axial stress sigma_v [kPa]")
        ax.set_ylabel("void ratio e")
        ax.set_title("Cc = {}, Cs = {}".format(fmt(summary.get("Cc")), fmt(summary.get("Cs"))), fontsize=9)
        axk.set_xlabel("axial stress sigma_v [kPa]")
        axk.set_ylabel("lateral stress sigma_h [kPa]")
        axk.set_title("K0 = {} (loading), {} (end of unloading)".format(fmt(summary.get("K0")),
                                                                        fmt(summary.get("K0_unloading"))), fontsize=9)
        for a in (ax, axk):
            a.grid(alpha=0.3)
            a.legend(fontsize=8)
        fig.suptitle(title + " - oedometer", fontsize=10)
        fig.tight_layout()
        save(fig, os.path.join(out, "oedometer.png"))
        return
    if test == "cyclic-simple-shear" and "gamma" in data:
        fig, (ax, axg, axd) = plt.subplots(1, 3, figsize=(15.5, 4.2))
        g0 = data["gamma"][0]
        ax.plot([100.0 * (g - g0) for g in data["gamma"]], kpa("tau"), lw=0.8)
        ax.set_xlabel("shear strain gamma - gamma0 [%]")
        ax.set_ylabel("shear stress tau [kPa]")
        amps = summary.get("shear_strain_amplitudes") or []
        ratio = summary.get("G_over_Gmax") or []
        damping = summary.get("damping_ratio") or []
        if amps:
            axg.semilogx(amps, [r if r is not None else float("nan") for r in ratio], "o-")
            axd.semilogx(amps, [100.0 * d for d in damping], "s-")
        axg.set_xlabel("shear strain amplitude gamma_a")
        axg.set_ylabel("G / Gmax")
        axg.set_ylim(0.0, 1.1)
        axg.set_title("Gmax = {} MPa".format(fmt(summary.get("Gmax_MPa"))), fontsize=9)
        axd.set_xlabel("shear strain amplitude gamma_a")
        axd.set_ylabel("damping ratio [%]")
        for a in (ax, axg, axd):
            a.grid(alpha=0.3, which="both")
        fig.suptitle(title + " - cyclic simple shear", fontsize=10)
        fig.tight_layout()
        save(fig, os.path.join(out, "cyclic_simple_shear.png"))
        return
    if test == "stress-path" and "s" in data:
        fig, (ax, axs, axe) = plt.subplots(1, 3, figsize=(15.5, 4.2))
        ax.plot(kpa("p"), kpa("q"), ".-", ms=2, lw=1.1)
        ax.set_xlabel("mean effective stress p' [kPa]")
        ax.set_ylabel("deviator q [kPa]")
        ax.set_xlim(left=0.0)
        for key, label in (("sigma2", "sigma_xx"), ("sigma3", "sigma_yy"), ("sigma1", "sigma_zz")):
            axs.plot(data["s"], kpa(key), lw=1.0, label=label)
        axs.set_xlabel("path variable s")
        axs.set_ylabel("normal stress [kPa]")
        for key, label in (("eps2", "eps_xx"), ("eps3", "eps_yy"), ("eps1", "eps_zz"), ("eps_v", "eps_v")):
            axe.plot(data["s"], [100.0 * v for v in data[key]], lw=1.0, label=label)
        axe.set_xlabel("path variable s")
        axe.set_ylabel("strain [%] (compression positive)")
        for a in (ax, axs, axe):
            a.grid(alpha=0.3)
        axs.legend(fontsize=8)
        axe.legend(fontsize=8)
        ax.set_title("completed" if summary.get("path_completed") else "stopped before the end of the path", fontsize=9)
        fig.suptitle(title + " - stress path", fontsize=10)
        fig.tight_layout()
        save(fig, os.path.join(out, "stress_path.png"))
        return
    if "u" not in data and test != "cyclic-triaxial":
        return
    cyclic = test == "cyclic-triaxial"
    panels = 3 if cyclic else 2
    fig, axes = plt.subplots(1, panels, figsize=(5.3 * panels, 4.2))
    ax = axes[0]
    ax.plot(kpa("p"), kpa("q"), lw=1.1)
    ax.set_xlabel("mean effective stress p' [kPa]")
    ax.set_ylabel("deviator q [kPa]")
    ax.set_xlim(left=0.0)
    ax.grid(alpha=0.3)
    if cyclic:
        axes[1].plot([100.0 * v for v in data["eps1"]], kpa("q"), lw=1.0)
        axes[1].set_xlabel("axial strain eps1 [%]")
        axes[1].set_ylabel("deviator q [kPa]")
        axes[1].grid(alpha=0.3)
        axr = axes[2]
        # Cycles as a continuous axis: the records at the reversals (where `cycle` steps by a half)
        # are exact, the others interpolated in step between them.
        knots_s, knots_c = [data["step"][0]], [0.0]
        for s_, c_, prev in zip(data["step"][1:], data["cycle"][1:], data["cycle"]):
            if c_ != prev:
                knots_s.append(s_)
                knots_c.append(c_)
        last_s = data["step"][-1]
        if knots_s[-1] != last_s:
            # The records after the last reversal belong to the half cycle the test ended in.
            knots_s.append(last_s)
            knots_c.append(knots_c[-1] + 0.5)
        cycles = [interp(s_, knots_s, knots_c) for s_ in data["step"]]
        if "u" in data:
            axr.plot(cycles, [1.0 - v / p0 for v in data["p"]], lw=1.0, label="ru = 1 - p'/p0")
            axr.plot(cycles, [v / p0 for v in data["u"]], lw=0.6, alpha=0.6, label="u/p0")
            axr.set_ylabel("excess pore-pressure ratio")
            axr.legend(fontsize=8)
        else:
            axr.plot(cycles, [100.0 * v for v in data["eps1"]], lw=1.0)
            axr.set_ylabel("axial strain eps1 [%]")
        axr.set_xlabel("cycles")
        axr.grid(alpha=0.3)
        n = summary.get("n_cycles_to_liquefaction")
        axes[0].set_title("CSR = {}, N_liq = {}".format(fmt(summary.get("csr")), fmt(n)), fontsize=9)
        name = "cyclic.png"
    else:
        axu = axes[1]
        axu.plot([100.0 * v for v in data["eps1"]], kpa("u"), lw=1.1)
        axu.axhline(0.0, color="k", lw=0.5)
        axu.set_xlabel("axial strain eps1 [%]")
        axu.set_ylabel("excess pore pressure u [kPa]")
        axu.grid(alpha=0.3)
        axes[0].set_title("p'_min = {} kPa, liquefied: {}".format(fmt((summary.get("p_min") or 0) / 1e3),
                                                                    summary.get("liquefied")), fontsize=9)
        name = "undrained.png"
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save(fig, os.path.join(out, name))


def interp(x, xs, ys):
    for i in range(1, len(xs)):
        if x <= xs[i]:
            f = (x - xs[i - 1]) / (xs[i] - xs[i - 1]) if xs[i] > xs[i - 1] else 1.0
            return ys[i - 1] + f * (ys[i] - ys[i - 1])
    return ys[-1]


def fmt(v):
    return "null" if v is None else "{:.3g}".format(v)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
