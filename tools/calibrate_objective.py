"""The calibration's problem: parameter space, what a run gives, and the objective (docs/calibration.md).

The optimiser works in unit coordinates u in [0, 1]^n, one per free parameter, mapped linearly or
logarithmically onto [min, max]: every parameter then spans the same range, which is what a
trust-region or simplex method's steps assume.

The objective compares the seed-mean of each output with its target:

    F = sum_targets w (mean - value)^2 / scale^2 + sum_curve_quantities w * mean_grid (mean - lab)^2 / scale^2

written as F = r.r with the residual vector r (one entry per scalar target, one per grid point of
each curve quantity, the latter carrying 1/N so that a curve counts as one target of its weight)."""
import csv
import difflib
import math

import numpy as np


class InputProblem(Exception):
    """A target the runs cannot provide (exit 2, like any bad input)."""


class Space:
    """Free parameters: unit coordinates <-> values <-> --set overrides."""

    def __init__(self, parameters):
        self.parameters = parameters
        self.keys = [p["key"] for p in parameters]

    def __len__(self):
        return len(self.parameters)

    def value(self, j, u):
        p = self.parameters[j]
        if u <= 0.0:
            return float(p["min"])
        if u >= 1.0:
            return float(p["max"])
        if p["log"]:
            return float(math.exp(math.log(p["min"]) + u * (math.log(p["max"]) - math.log(p["min"]))))
        return float(p["min"] + u * (p["max"] - p["min"]))

    def unit(self, j, value):
        p = self.parameters[j]
        if p["log"]:
            return (math.log(value) - math.log(p["min"])) / (math.log(p["max"]) - math.log(p["min"]))
        return (value - p["min"]) / (p["max"] - p["min"])

    def values(self, u):
        return [self.value(j, float(x)) for j, x in enumerate(u)]

    def start(self):
        return [self.unit(j, p["start"]) for j, p in enumerate(self.parameters)]

    def sets(self, u):
        # repr() is the shortest text that reads back as the same double, and valid TOML.
        return [f"{key}={value!r}" for key, value in zip(self.keys, self.values(u))]

    def dvalue_du(self, j, u):
        """d value / d u at u: the factor from unit-coordinate derivatives to parameter units."""
        p = self.parameters[j]
        if p["log"]:
            return self.value(j, u) * (math.log(p["max"]) - math.log(p["min"]))
        return p["max"] - p["min"]


def summary_value(summary, key):
    """A (possibly nested, dotted) key of summary.json: a float, None when the run reports null, or
    raises KeyError when the summary has no such key at all."""
    node = summary
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            raise KeyError(key)
        node = node[part]
    if node is None:
        return None
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise KeyError(key)
    return float(node) if math.isfinite(node) else None


def numeric_keys(summary, prefix=""):
    keys = []
    for k, v in summary.items():
        if isinstance(v, dict):
            keys += numeric_keys(v, prefix + k + ".")
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            keys.append(prefix + k)
    return keys


class Problem:
    """Targets, the laboratory curves on their grids, and the objective.

    A target file may name several confining pressures (docs/calibration.md, "Several pressures"):
    each is a condition, one run per condition and seed; every target and curve belongs to one
    (its "condition" id, "" when the file names only the config's pressure). Targets are told apart
    by their label t["key"] ("phi_peak_deg", or "phi_peak_deg@100kPa" with several pressures), the
    value read from the summary is t["summary_key"]; curve quantities likewise ("q", "q@100kPa")."""

    def __init__(self, target):
        self.targets = target["targets"]
        curves = target.get("curves")
        if curves is None:  # a calibration.json of one [curve], before several pressures
            curves = [dict(target["curve"], label="curve", condition="")] if target.get("curve") else []
        self.curves = curves
        self.conditions = target.get("conditions") or [{"id": "", "confining_pressure": None, "sets": []}]
        self.entries = []  # the curve quantities, flattened: label, column name, weight, scale, curve, grid
        self.lab = {}
        for c in curves:
            grid = np.linspace(c["eps1_min"], c["eps1_max"], c["points"])
            for q in c["quantities"]:
                label = q.get("label", q["name"])
                self.entries.append({"label": label, "name": q["name"], "weight": q["weight"], "scale": q["scale"],
                                     "curve": c, "grid": grid})
                self.lab[label] = np.interp(grid, c["data"]["eps1"], c["data"][q["name"]])

    def quantities(self):
        """The labels of the curve quantities (the keys of a run's curves)."""
        return [e["label"] for e in self.entries]

    def outputs(self, run_dir, summary, condition=""):
        """What one completed run of a condition gives: its targets' values and its curves on their
        grids. Returns (values, curves, problem): problem names what could not be measured, or is None."""
        values = {}
        problem = None
        for t in self.targets:
            if t.get("condition", "") != condition:
                continue
            key = t.get("summary_key", t["key"])
            try:
                v = summary_value(summary, key)
            except KeyError:
                keys = numeric_keys(summary)
                # The closest keys first: the whole list is cut to stay one readable line.
                close = difflib.get_close_matches(key, keys, n=3, cutoff=0.5)
                hint = f"closest: {', '.join(close)}; " if close else ""
                raise InputProblem(
                    f"target error: target {key!r}: not a numeric key of summary.json "
                    f"({hint}numeric keys: {', '.join(keys)[:600]})") from None
            values[t["key"]] = v
            if v is None:
                problem = problem or f"{t['key']} was not measured (null)"
        curves = {}
        mine = [e for e in self.entries if e["curve"].get("condition", "") == condition]
        if mine:
            series = read_timeseries(f"{run_dir}/timeseries.csv")
            eps1 = series["eps1"]
            for e in mine:
                grid = e["grid"]
                if eps1[-1] < grid[-1] * (1.0 - 1e-9):
                    problem = problem or f"the run ends at eps1 = {eps1[-1]:.4g} before the grid's {grid[-1]:.4g}"
                curves[e["label"]] = np.interp(grid, eps1, simulated_quantity(series, e["name"])).tolist()
        return values, curves, problem

    def residuals(self, values, curves):
        """The residual vector r of one set of outputs (seed-mean or a single seed)."""
        r = [math.sqrt(t["weight"]) * (values[t["key"]] - t["value"]) / t["scale"] for t in self.targets]
        for e in self.entries:
            factor = math.sqrt(e["weight"] / len(e["grid"])) / e["scale"]
            r += list(factor * (np.asarray(curves[e["label"]]) - self.lab[e["label"]]))
        return np.asarray(r, dtype=float)

    def objective(self, values, curves):
        """F = r.r, summed exactly rounded (math.fsum): the value, and so the optimiser's path that a
        resumed calibration replays, must not depend on the BLAS library or the CPU's vector width
        (a dot product through OpenBLAS differs from the reference BLAS in the last bits)."""
        return math.fsum(x * x for x in self.residuals(values, curves).tolist())

    def output_scales(self):
        """Per residual entry: d r / d output (the weight over the scale)."""
        c = [math.sqrt(t["weight"]) / t["scale"] for t in self.targets]
        for e in self.entries:
            c += [math.sqrt(e["weight"] / len(e["grid"])) / e["scale"]] * len(e["grid"])
        return np.asarray(c, dtype=float)

    def output_vector(self, values, curves):
        y = [values[t["key"]] for t in self.targets]
        for e in self.entries:
            y += list(curves[e["label"]])
        return np.asarray(y, dtype=float)

    def entry_offsets(self):
        """(entry, first index in the output vector) of every curve quantity."""
        out, offset = [], len(self.targets)
        for e in self.entries:
            out.append((e, offset))
            offset += len(e["grid"])
        return out


def read_timeseries(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no records")
    return {k: np.array([float(r[k]) for r in rows]) for k in ("eps1", "eps_v", "q", "sigma1", "sigma2", "sigma3")}


def simulated_quantity(series, name):
    if name == "sigma1_over_sigma3":
        # The lateral stress of a triaxial test: the mean of the two lateral walls (as macro.cpp).
        return series["sigma1"] / (0.5 * (series["sigma2"] + series["sigma3"]))
    return series[name]


def seed_statistics(per_seed):
    """Mean and sample standard deviation (None with one seed) over seeds of equal-length outputs,
    summed exactly rounded (math.fsum) for the same reason as the objective."""
    a = np.asarray(per_seed, dtype=float)
    columns = a.reshape(len(a), -1).T.tolist()
    n = len(a)
    mean = [math.fsum(c) / n for c in columns]
    std = [math.sqrt(math.fsum((x - m) ** 2 for x in c) / (n - 1)) for c, m in zip(columns, mean)] if n > 1 else None
    shape = a.shape[1:]
    return np.reshape(mean, shape), None if std is None else np.reshape(std, shape)
