"""What a calibration reports: fit quality, sensitivities and identifiability at the optimum, the
calibrated config, plots (docs/calibration.md explains each quantity).

Sensitivities are finite differences of the seed-mean outputs between the best point and its
neighbours at +-step (unit coordinates), all evaluated with the same seeds (common random numbers,
so that the difference is not swamped by the sample-to-sample scatter). With J the Jacobian of the
weighted residual vector r with respect to the unit coordinates u:

  * singular values of J and the condition number sigma_max / sigma_min: how much worse the
    best-determined combination of parameters is pinned down than the worst;
  * the correlation of the parameter estimates, from (J^T J)^-1 (the Gauss-Newton covariance up to
    a factor): |rho| near 1 means two parameters trade off -- the targets fix a combination of
    them, not each one;
  * the scatter of the calibrated parameters due to the seeds: the linearised least-squares
    estimate moves by du = -(J^T J)^-1 J^T dr, so with S the covariance of the seed-mean residual
    vector (from the per-seed residuals) cov(u) = C J^T S J C, C = (J^T J)^-1 (the sandwich form,
    valid although the points of a curve are correlated)."""
import csv
import io
import json
import math
import os
import subprocess

import numpy as np

TRADE_OFF_CORRELATION = 0.9


def _none_if_nan(x):
    return None if x is None or not math.isfinite(x) else float(x)


def derivatives(best, neighbours, n):
    """dy/du per parameter (columns; None where a neighbour failed) of the seed-mean output vector."""
    y0 = np.mean(best["per_seed_outputs"], axis=0)
    columns = []
    for j in range(n):
        side = {}
        for jj, e in neighbours:
            if jj == j and e["failed"] is None:
                side["plus" if e["u"][j] > best["u"][j] else "minus"] = (e["u"][j], np.mean(e["per_seed_outputs"], axis=0))
        if "plus" in side and "minus" in side:
            (up, yp), (um, ym) = side["plus"], side["minus"]
            columns.append((yp - ym) / (up - um))
        elif side:
            ((u1, y1),) = side.values()
            columns.append((y1 - y0) / (u1 - best["u"][j]))
        else:
            columns.append(None)
    return columns


def analyse(space, problem, best, neighbours, step):
    n = len(space)
    columns = derivatives(best, neighbours, n)
    measured = [j for j in range(n) if columns[j] is not None]
    out = {"step": step, "parameters_measured": [space.keys[j] for j in measured],
           "parameters_not_measured": [space.keys[j] for j in range(n) if columns[j] is None]}
    if not measured:
        return out
    c = problem.output_scales()
    J_out = np.column_stack([columns[j] for j in measured])
    J = c[:, None] * J_out
    singular = np.linalg.svd(J, compute_uv=False)
    out["singular_values"] = singular.tolist()
    out["condition_number"] = _none_if_nan(singular[0] / singular[-1]) if singular[-1] > 0 else None
    H = J.T @ J
    C = np.linalg.pinv(H)
    d = np.sqrt(np.clip(np.diag(C), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = C / np.outer(d, d)
        norms = np.linalg.norm(J, axis=0)
        cos = (J.T @ J) / np.outer(norms, norms)
    keys = [space.keys[j] for j in measured]
    out["correlation"] = {a: {b: _none_if_nan(corr[i, k]) for k, b in enumerate(keys)} for i, a in enumerate(keys)}
    out["collinearity"] = {a: {b: _none_if_nan(cos[i, k]) for k, b in enumerate(keys)} for i, a in enumerate(keys)}

    # Seed scatter of the calibrated values (sandwich form, see the module's docstring).
    per_seed = np.asarray(best["per_seed_outputs"])
    target_vector = problem.output_vector({t["key"]: t["value"] for t in problem.targets},
                                          {q: problem.lab[q] for q in problem.quantities()})
    scatter = {}
    if len(per_seed) > 1:
        R = c * (per_seed - target_vector)
        S = np.cov(R, rowvar=False, ddof=1).reshape(len(c), len(c)) / len(per_seed)
        cov_u = C @ J.T @ S @ J @ C
        for i, j in enumerate(measured):
            scatter[space.keys[j]] = float(math.sqrt(max(cov_u[i, i], 0.0)) * abs(space.dvalue_du(j, best["u"][j])))
    out["parameter_seed_scatter"] = scatter

    # Per target: how much each parameter moves it, in three normalisations.
    mean0 = np.mean(per_seed, axis=0)
    std0 = np.std(per_seed, axis=0, ddof=1) if len(per_seed) > 1 else None
    n_seeds = len(per_seed)
    table = {}
    rows = [(t["key"], [i], t["scale"]) for i, t in enumerate(problem.targets)]
    for e, offset in problem.entry_offsets():
        rows.append((f"curve:{e['label']}", list(range(offset, offset + len(e["grid"]))), e["scale"]))
    for name, idx, scale in rows:
        entry = {}
        for i, j in enumerate(measured):
            dydu = J_out[idx, i]
            theta = best["parameters"][space.keys[j]]
            dydtheta = dydu / space.dvalue_du(j, best["u"][j])
            cell = {"range_effect": float(np.sqrt(np.mean((dydu / scale) ** 2)))}
            if len(idx) == 1:
                cell["range_effect"] = float(dydu[0] / scale)  # signed for a single value
                cell["derivative"] = float(dydtheta[0])
                cell["elasticity"] = _none_if_nan(dydtheta[0] * theta / mean0[idx[0]]) if mean0[idx[0]] != 0 and theta != 0 else None
            if std0 is not None:
                # The change over the whole range against the seed scatter of the mean (points
                # without scatter, e.g. eps_v = 0 at eps1 = 0, say nothing and are left out).
                noise = std0[idx] / math.sqrt(n_seeds)
                seen = noise > 0
                if seen.any():
                    cell["range_over_scatter"] = float(np.sqrt(np.mean((dydu[seen] / noise[seen]) ** 2)))
            entry[space.keys[j]] = cell
        table[name] = entry
    out["sensitivity"] = table
    out["statements"] = statements(space, keys, corr, norms, scatter)
    lower = [e for _, e in neighbours if e["failed"] is None and e["objective"] < best["objective"]]
    if lower:
        e = min(lower, key=lambda e: e["objective"])
        # Within the roughness of a chaotic objective, or a budget too small to converge.
        out["statements"].append(
            f"A finite-difference neighbour fits better ({e['name']}: objective {e['objective']:.4g} against "
            f"{best['objective']:.4g}): the optimum is not resolved more finely than the step; compare the "
            f"difference with the seed scatter above, or continue with a larger budget.")
    return out


def statements(space, keys, corr, norms, scatter):
    """Plain sentences on identifiability: trade-offs, and parameters the targets do not pin down."""
    said = []
    for i in range(len(keys)):
        for k in range(i + 1, len(keys)):
            if math.isfinite(corr[i, k]) and abs(corr[i, k]) >= TRADE_OFF_CORRELATION:
                # Negatively correlated estimates: both parameters push the targets the same way,
                # so raising one while lowering the other leaves the fit nearly unchanged.
                how = "raising one while lowering the other" if corr[i, k] < 0 else "raising or lowering both together"
                said.append(f"{keys[i]} and {keys[k]} trade off (estimate correlation {corr[i, k]:+.2f}): the targets "
                            f"fix mainly a combination of them, and {how} changes the fit little. Add a target that "
                            f"they move differently, or fix one of them.")
    for i, key in enumerate(keys):
        p = space.parameters[space.keys.index(key)]
        width = p["max"] - p["min"]
        if norms.max() > 0 and norms[i] < 1e-3 * norms.max():
            said.append(f"{key}: the targets hardly depend on it (sensitivity {norms[i] / norms.max():.1e} of the "
                        f"largest); it is not identifiable from them.")
        elif key in scatter and scatter[key] > 0.25 * width:
            said.append(f"{key}: the seed scatter leaves it uncertain by +-{scatter[key]:.3g}, more than a quarter of "
                        f"its range [{p['min']:g}, {p['max']:g}]: more seeds or grains (less scatter), or a target "
                        f"more sensitive to it, would pin it down.")
    if not said:
        said.append(f"No pair of parameters trades off (every |correlation| < {TRADE_OFF_CORRELATION}), and the seed "
                    "scatter leaves each parameter within a quarter of its range.")
    return said


def fit_quality(problem, best):
    fit = {"targets": [], "curves": []}
    for t in problem.targets:
        v = best["values"][t["key"]]
        diff = v["mean"] - t["value"]
        fit["targets"].append({"key": t["key"], "target": t["value"], "calibrated": v["mean"], "seed_std": v["std"],
                               "per_seed": v["per_seed"], "difference": diff, "relative": diff / t["scale"],
                               "contribution": t["weight"] * (diff / t["scale"]) ** 2,
                               "within_seed_scatter": None if v["std"] is None else abs(diff) <= v["std"]})
    for q in problem.entries:
        err = np.asarray(best["curves"][q["label"]]["mean"]) - problem.lab[q["label"]]
        fit["curves"].append({"quantity": q["label"], "rms_error": float(np.sqrt(np.mean(err ** 2))),
                              "max_abs_error": float(np.max(np.abs(err))), "scale": q["scale"],
                              "relative_rms": float(np.sqrt(np.mean(err ** 2)) / q["scale"]),
                              "contribution": float(q["weight"] * np.mean((err / q["scale"]) ** 2))})
    return fit


def best_toml(folder, inputs, space, best, grainlab):
    """The config with the calibrated values, every key written out (`grainlab check`)."""
    argv = [grainlab, "check", inputs["config"]]
    for assignment in space.sets(best["u"]):
        argv += ["--set", assignment]
    proc = subprocess.run(argv, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"grainlab check of the calibrated config failed: {proc.stderr.strip()}")
    header = [f"# Calibrated by grainlab calibrate from {inputs['config']}",
              f"# target {inputs['target_file']}; best evaluation {best['name']}, objective {best['objective']:.6g}"]
    header += [f"#   {k} = {v!r}" for k, v in best["parameters"].items()]
    path = os.path.join(folder, "best.toml")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(header) + "\n" + proc.stdout)
    os.replace(path + ".tmp", path)


def plots(folder, problem, history, best):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out = os.path.join(folder, "plots")
    os.makedirs(out, exist_ok=True)
    start = history[0]

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(os.path.join(out, name + ".tmp.png"), dpi=110)
        plt.close(fig)
        os.replace(os.path.join(out, name + ".tmp.png"), os.path.join(out, name))

    labels = {"q": ("deviator stress q [kPa]", 1e-3), "sigma1_over_sigma3": ("sigma1/sigma3 [-]", 1.0),
              "eps_v": ("volumetric strain eps_v [%] (contraction +)", 100.0)}
    if problem.entries:
        entries = problem.entry_offsets()
        fig, axes = plt.subplots(1, len(entries), figsize=(5.5 * len(entries), 4.2), squeeze=False)
        for ax, (e, offset) in zip(axes[0], entries):
            label, f = labels[e["name"]]
            data = e["curve"]["data"]
            x = 100 * e["grid"]
            ax.plot([100 * v for v in data["eps1"]], [f * v for v in data[e["name"]]], "k.-", lw=1, ms=3,
                    label="target (laboratory)")
            for k, y in enumerate(best["per_seed_outputs"]):
                ax.plot(x, f * y[offset:offset + len(x)], color="tab:red", lw=0.6, alpha=0.5,
                        label="calibrated, each seed" if k == 0 else None)
            ax.plot(x, f * np.asarray(best["curves"][e["label"]]["mean"]), color="tab:red", lw=2, label="calibrated, seed mean")
            if start["failed"] is None and start is not best:
                ax.plot(x, f * np.asarray(start["curves"][e["label"]]["mean"]), color="grey", ls="--", lw=1.2,
                        label="start point")
            if e["label"] != e["name"]:
                ax.set_title(e["label"], fontsize=9)
            ax.set_xlabel("axial strain eps1 [%]")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        save(fig, "fit_curves.png")
    if problem.targets:
        fig, ax = plt.subplots(figsize=(6.5, 1.6 + 0.5 * len(problem.targets)))
        for i, t in enumerate(problem.targets):
            v = best["values"][t["key"]]
            ax.errorbar(v["mean"] / t["value"] if t["value"] else v["mean"], i, xerr=(v["std"] or 0) / abs(t["value"] or 1),
                        fmt="o", color="tab:red", capsize=3, label="calibrated (+- seed std)" if i == 0 else None)
            ax.plot([s / t["value"] if t["value"] else s for s in v["per_seed"]], [i] * len(v["per_seed"]), "|",
                    color="tab:red", alpha=0.5)
            if start["failed"] is None and start is not best:
                sv = start["values"][t["key"]]["mean"]
                ax.plot(sv / t["value"] if t["value"] else sv, i, "x", color="grey", label="start point" if i == 0 else None)
        ax.axvline(1.0, color="k", lw=1, label="target")
        ax.set_yticks(range(len(problem.targets)), [t["key"] for t in problem.targets])
        ax.set_xlabel("value / target")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        save(fig, "fit_values.png")
    fig, ax = plt.subplots(figsize=(6.5, 4))
    opt = [e for e in history if e["kind"] == "optimizer"]
    ok = [e for e in opt if e["failed"] is None]
    ax.semilogy([e["index"] for e in ok], [e["objective"] for e in ok], "o", ms=4, label="evaluation")
    bad = [e for e in opt if e["failed"] is not None]
    if bad:
        ax.semilogy([e["index"] for e in bad], [e["objective"] for e in bad], "x", color="tab:red", label="failed (penalty)")
    running = np.minimum.accumulate([e["objective"] for e in opt])
    ax.semilogy([e["index"] for e in opt], running, "-", color="k", lw=1.2, label="best so far")
    ax.set_xlabel("evaluation")
    ax.set_ylabel("objective")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    save(fig, "convergence.png")


def _fmt(x, digits=4):
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return f"{x:.{digits}g}"


def report_markdown(inputs, space, problem, history, best, fit, analysis, meta):
    t = inputs["target"]
    lines = ["# Calibration report", "",
             f"Config `{inputs['config']}`, target `{inputs['target_file']}`; seeds {t['seeds']}; optimiser "
             f"{t['optimizer']['algorithm']} (NLopt), budget {t['optimizer']['max_evaluations']} evaluations: "
             f"{sum(e['kind'] == 'optimizer' for e in history)} evaluated, stopped: {meta['stop_reason']}.", "",
             *([f"Each evaluation runs every seed at {len(problem.conditions)} confining pressures ("
                + ", ".join(f"{c['confining_pressure'] / 1e3:g} kPa" for c in problem.conditions)
                + "); a target or curve labelled @P kPa is compared with the runs at that pressure.", ""]
               if len(problem.conditions) > 1 else []),
             "## Calibrated parameters", "",
             "| parameter | value | seed scatter (1 sigma) | bounds | start | at a bound |", "|---|---|---|---|---|---|"]
    scatter = analysis.get("parameter_seed_scatter", {}) if analysis else {}
    for j, p in enumerate(space.parameters):
        v = best["parameters"][p["key"]]
        at = "yes" if best["u"][j] in (0.0, 1.0) else "no"
        lines.append(f"| {p['key']} | {v:.6g} | {_fmt(scatter.get(p['key']))} | [{p['min']:g}, {p['max']:g}]"
                     f"{' log' if p['log'] else ''} | {p['start']:g} | {at} |")
    n_seeds = len(t["seeds"])
    if n_seeds < 4:
        lines += ["", f"The seed scatter is estimated from {n_seeds} seed(s) ({max(n_seeds - 1, 0)} degree(s) of freedom): "
                  "a rough figure; four or more seeds make it usable."]
    lines += ["", f"Objective {best['objective']:.5g} at {best['name']} (start {history[0]['objective']:.5g}); "
              f"per seed: {', '.join(_fmt(x) for x in best['objective_per_seed'])}.", "",
              "## Fit per target", ""]
    if fit["targets"]:
        lines += ["| target | value | calibrated (seed mean) | seed std | difference | / scale | contribution |",
                  "|---|---|---|---|---|---|---|"]
        for f in fit["targets"]:
            lines.append(f"| {f['key']} | {f['target']:.5g} | {f['calibrated']:.5g} | {_fmt(f['seed_std'])} | "
                         f"{f['difference']:+.4g} | {f['relative']:+.3f} | {f['contribution']:.4g} |")
    if fit["curves"]:
        lines += ["", "| curve | RMS error | max error | RMS / scale | contribution |", "|---|---|---|---|---|"]
        for f in fit["curves"]:
            lines.append(f"| {f['quantity']} | {f['rms_error']:.4g} | {f['max_abs_error']:.4g} | {f['relative_rms']:.3f} | "
                         f"{f['contribution']:.4g} |")
    lines += ["", "Plots: `plots/fit_curves.png`, `plots/fit_values.png`, `plots/convergence.png`.", ""]
    if analysis:
        keys = analysis["parameters_measured"]
        lines += ["## Sensitivity at the optimum", "",
                  f"Finite differences at +-{analysis['step']} of each parameter's range (same seeds). Range effect: "
                  "the target's change over the whole parameter range, in units of its scale (RMS over a curve's points); "
                  "el.: elasticity, % change of the target per % change of the parameter; x scatter: the change over "
                  "the whole range in units of the seed scatter of the mean.", "",
                  "| target | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]
        for name, entry in analysis["sensitivity"].items():
            cells = []
            for k in keys:
                cell = entry[k]
                text = f"{cell['range_effect']:+.3g}"
                if cell.get("elasticity") is not None:
                    text += f", el. {cell['elasticity']:+.2g}"
                if cell.get("range_over_scatter") is not None:
                    text += f", {cell['range_over_scatter']:.2g}x scatter"
                cells.append(text)
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines += ["", "## Identifiability", "",
                  f"Singular values of the weighted Jacobian: {', '.join(f'{s:.3g}' for s in analysis['singular_values'])}; "
                  f"condition number {_fmt(analysis['condition_number'])}.", "",
                  "Correlation of the estimates (from (J^T J)^-1) | collinearity of the sensitivity columns (cosine):", "",
                  "| | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]
        for a in keys:
            lines.append(f"| {a} | " + " | ".join(f"{_fmt(analysis['correlation'][a][b], 3)} / "
                                                   f"{_fmt(analysis['collinearity'][a][b], 3)}" for b in keys) + " |")
        lines += [""] + [f"- {s}" for s in analysis["statements"]]
        if analysis["parameters_not_measured"]:
            lines.append(f"- Not measured (a neighbour evaluation failed): {', '.join(analysis['parameters_not_measured'])}.")
    else:
        lines += ["## Sensitivity", "", "Not evaluated ([sensitivity] enabled = false, or every neighbour failed)."]
    lines += ["", f"Runs started in the last session: {meta['runs_started_this_session']} "
              f"({meta['seconds_this_session']:.0f} s); every run is under `runs/`, every evaluation in "
              "`evaluations.jsonl` / `evaluations.csv`; the calibrated config is `best.toml`.", ""]
    return "\n".join(lines)


def evaluations_csv(space, problem, history):
    buffer = io.StringIO()
    w = csv.writer(buffer, lineterminator="\n")
    keys = [t["key"] for t in problem.targets]
    w.writerow(["index", "name", "kind"] + space.keys + ["objective", "failed"] + [f"{k}_mean" for k in keys]
               + [f"{k}_std" for k in keys])
    for e in history:
        means = [e["values"][k]["mean"] if e["values"] else "" for k in keys]
        stds = [e["values"][k]["std"] if e["values"] and e["values"][k]["std"] is not None else "" for k in keys]
        w.writerow([e["index"], e["name"], e["kind"]] + [repr(e["parameters"][k]) for k in space.keys]
                   + [repr(e["objective"]), e["failed"] or ""] + means + stds)
    return buffer.getvalue()


def write(folder, inputs, space, problem, history, best, neighbours, meta):
    analysis = None
    if neighbours:
        analysis = analyse(space, problem, best, neighbours, inputs["target"]["sensitivity"]["step"])
    fit = fit_quality(problem, best)
    best_toml(folder, inputs, space, best, meta["grainlab"])
    plots(folder, problem, history, best)
    result = {"status": "completed", "stop_reason": meta["stop_reason"],
              "best": {"evaluation": best["name"], "parameters": best["parameters"], "unit": best["u"],
                       "objective": best["objective"], "objective_per_seed": best["objective_per_seed"]},
              "start": {"parameters": history[0]["parameters"], "objective": history[0]["objective"]},
              "fit": fit, "sensitivity": analysis, "seeds": inputs["target"]["seeds"],
              "evaluations": len(history), "runs_started_this_session": meta["runs_started_this_session"]}
    with open(os.path.join(folder, "result.json.tmp"), "w") as f:
        json.dump(result, f, indent=1)
    os.replace(os.path.join(folder, "result.json.tmp"), os.path.join(folder, "result.json"))
    with open(os.path.join(folder, "evaluations.csv"), "w") as f:
        f.write(evaluations_csv(space, problem, history))
    with open(os.path.join(folder, "report.md"), "w") as f:
        f.write(report_markdown(inputs, space, problem, history, best, fit, analysis, meta))
