"""The calibration's arithmetic, without runs: parameter mapping, objective, and the sensitivity /
identifiability analysis against independent numbers (hand computations, numpy's own routines on
the known Jacobian, and a Monte Carlo of the least-squares estimate for the seed scatter)."""
import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
import calibrate_report  # noqa: E402
from calibrate_objective import Problem, Space, summary_value  # noqa: E402


def test_space_maps_bounds_linear_and_log_and_writes_toml_floats():
    space = Space([{"key": "contact.friction_deg", "min": 20.0, "max": 40.0, "start": 25.0, "log": False},
                   {"key": "contact.young", "min": 1e9, "max": 1e11, "start": 1e10, "log": True}])
    assert space.values([0.0, 0.0]) == [20.0, 1e9]
    assert space.values([1.0, 1.0]) == [40.0, 1e11]
    # log: the middle of [1e9, 1e11] is the geometric mean 1e10
    assert space.value(1, 0.5) == pytest.approx(1e10, rel=1e-12)
    assert space.value(0, 0.25) == pytest.approx(25.0, rel=1e-15)
    assert space.start() == pytest.approx([0.25, 0.5])
    # d value / d u: the range (linear), value * ln(max/min) (log)
    assert space.dvalue_du(0, 0.3) == 20.0
    assert space.dvalue_du(1, 0.5) == pytest.approx(1e10 * math.log(100.0), rel=1e-12)
    sets = space.sets([0.3, 0.7])
    assert sets[0].startswith("contact.friction_deg=") and float(sets[0].split("=")[1]) == space.value(0, 0.3)
    assert float(sets[1].split("=")[1]) == space.value(1, 0.7)


def test_summary_value_nested_null_and_missing():
    summary = {"phi_peak_deg": 41.5, "E0_MPa": None, "grading": {"d50": 5e-3}, "status": "completed", "flag": True}
    assert summary_value(summary, "phi_peak_deg") == 41.5
    assert summary_value(summary, "grading.d50") == 5e-3
    assert summary_value(summary, "E0_MPa") is None  # could not be measured
    for missing in ("psi_max_deg", "grading.d60", "status", "flag"):
        with pytest.raises(KeyError):
            summary_value(summary, missing)


def curve_problem():
    # Laboratory q rises linearly to 200 kPa at 1 %, eps_v falls linearly to -0.4 %; scalar target phi 40.
    target = {"targets": [{"key": "phi_peak_deg", "value": 40.0, "weight": 2.0, "scale": 40.0}],
              "curve": {"quantities": [{"name": "q", "weight": 1.0, "scale": 2e5},
                                       {"name": "eps_v", "weight": 0.5, "scale": 4e-3}],
                        "eps1_min": 0.0, "eps1_max": 0.01, "points": 11,
                        "data": {"eps1": [0.0, 0.004, 0.01], "q": [0.0, 0.8e5, 2e5], "eps_v": [0.0, -1.6e-3, -4e-3]}}}
    return Problem(target)


def test_objective_by_hand(tmp_path):
    problem = curve_problem()
    # A run whose q is 10 % above the laboratory's everywhere and whose eps_v is 1e-3 lower
    # (more dilation) everywhere but at eps1 = 0, recorded at other strains than the grid's.
    eps1 = np.linspace(0.0, 0.012, 7)
    q = 1.1 * 2e7 * eps1
    eps_v = -0.4 * eps1 - 1e-3 * (eps1 > 0)
    with open(tmp_path / "timeseries.csv", "w") as f:
        f.write("step,eps1,eps_v,q,sigma1,sigma2,sigma3\n")
        for i, (a, b, c) in enumerate(zip(eps1, eps_v, q)):
            f.write(f"{i},{a!r},{b!r},{c!r},{c + 1e5!r},1e5,1e5\n")
    values, curves, problem_text = problem.outputs(str(tmp_path), {"phi_peak_deg": 38.0})
    assert problem_text is None
    assert curves["q"] == pytest.approx(list(1.1 * 2e7 * np.linspace(0, 0.01, 11)), rel=1e-12)
    r = problem.residuals(values, curves)
    # scalar: sqrt(2) (38 - 40)/40; q: sqrt(1/11) * 0.1 * q_lab / 2e5 at each point;
    # eps_v: sqrt(0.5/11) * (-1e-3 after the first grid point's linear ramp) / 4e-3
    grid = np.linspace(0, 0.01, 11)
    eps_v_error = np.interp(grid, eps1, eps_v) - (-0.4 * grid)
    expected = (2.0 * (2.0 / 40.0) ** 2
                + np.mean((0.1 * 2e7 * grid / 2e5) ** 2)
                + 0.5 * np.mean((eps_v_error / 4e-3) ** 2))
    assert float(r @ r) == pytest.approx(expected, rel=1e-12)
    # sigma1/sigma3 from the wall stresses: (q + 1e5) / 1e5
    ratio = Problem({"targets": [], "curve": {"quantities": [{"name": "sigma1_over_sigma3", "weight": 1.0, "scale": 1.0}],
                                              "eps1_min": 0.0, "eps1_max": 0.01, "points": 11,
                                              "data": {"eps1": [0.0, 0.01], "sigma1_over_sigma3": [1.0, 3.0]}}})
    _, curves, _ = ratio.outputs(str(tmp_path), {"phi_peak_deg": 38.0})
    assert curves["sigma1_over_sigma3"] == pytest.approx(list(1.0 + 1.1 * 200.0 * grid), rel=1e-12)


def test_outputs_flag_unmeasured_and_short_runs(tmp_path):
    problem = curve_problem()
    with open(tmp_path / "timeseries.csv", "w") as f:
        f.write("eps1,eps_v,q,sigma1,sigma2,sigma3\n0,0,0,1e5,1e5,1e5\n0.005,0,1e5,2e5,1e5,1e5\n")
    _, _, text = problem.outputs(str(tmp_path), {"phi_peak_deg": None})
    assert "not measured" in text
    _, _, text = problem.outputs(str(tmp_path), {"phi_peak_deg": 30.0})
    assert "before the grid" in text


def linear_model(A, u_star, noise, targets, scales):
    """A fake calibration of y = A u + noise_seed (one row of noise per seed): the best point and its
    finite-difference neighbours evaluated with the same seeds (common random numbers)."""
    space = Space([{"key": f"p{j}", "min": 1.0, "max": 11.0, "start": 5.0, "log": False} for j in range(len(u_star))])
    problem = Problem({"targets": [{"key": f"y{i}", "value": targets[i], "weight": 1.0, "scale": scales[i]}
                                   for i in range(len(targets))], "curve": None})

    def evaluation(name, u):
        per_seed = [A @ np.asarray(u) + e for e in noise]
        mean = np.mean(per_seed, axis=0)
        values = {f"y{i}": float(mean[i]) for i in range(len(mean))}
        r = problem.residuals(values, {})
        return {"name": name, "u": list(u), "failed": None, "per_seed_outputs": per_seed, "objective": float(r @ r),
                "parameters": {f"p{j}": 10.0 * x + 1.0 for j, x in enumerate(u)},
                "values": {k: {"mean": v} for k, v in values.items()}}
    best = evaluation("best", u_star)
    neighbours = []
    for j in range(len(u_star)):
        for sign in (1, -1):
            u = list(u_star)
            u[j] += sign * 0.05
            neighbours.append((j, evaluation(f"n{j}{sign}", u)))
    return space, problem, best, neighbours


def test_identifiability_matches_numpy_on_a_known_jacobian():
    A = np.array([[3.0, 1.0], [1.0, 2.0], [0.5, -1.0]])
    scales = np.array([2.0, 1.0, 0.5])
    rng = np.random.default_rng(3)
    space, problem, best, neighbours = linear_model(A, [0.4, 0.6], rng.normal(0, 0.01, (3, 3)), [1.0, 1.0, 1.0], scales)
    out = calibrate_report.analyse(space, problem, best, neighbours, 0.05)
    J = A / scales[:, None]
    assert out["condition_number"] == pytest.approx(np.linalg.cond(J), rel=1e-9)
    C = np.linalg.inv(J.T @ J)
    assert out["correlation"]["p0"]["p1"] == pytest.approx(C[0, 1] / math.sqrt(C[0, 0] * C[1, 1]), rel=1e-9)
    cos = J[:, 0] @ J[:, 1] / (np.linalg.norm(J[:, 0]) * np.linalg.norm(J[:, 1]))
    assert out["collinearity"]["p0"]["p1"] == pytest.approx(cos, rel=1e-9)
    # Range effect of p0 on y0: dy/du / scale = 3 / 2; elasticity: dy/dtheta * theta / y
    cell = out["sensitivity"]["y0"]["p0"]
    assert cell["range_effect"] == pytest.approx(1.5, rel=1e-9)
    y0 = np.mean(best["per_seed_outputs"], axis=0)[0]
    assert cell["elasticity"] == pytest.approx(3.0 / 10.0 * best["parameters"]["p0"] / y0, rel=1e-9)


def test_seed_scatter_of_the_parameters_agrees_with_monte_carlo():
    # The least-squares estimate u = argmin |diag(c) (A u - t)|^2 with mean outputs of n seeds:
    # its scatter over many independent sets of seeds is what the sandwich formula predicts.
    A = np.array([[3.0, 1.0], [1.0, 2.0], [0.5, -1.0]])
    scales = np.array([2.0, 1.0, 0.5])
    sigma = np.array([0.3, 0.1, 0.2])
    n = 400
    rng = np.random.default_rng(11)
    space, problem, best, neighbours = linear_model(A, [0.4, 0.6], rng.normal(0, sigma, (n, 3)), [1.0, 1.0, 1.0], scales)
    predicted = calibrate_report.analyse(space, problem, best, neighbours, 0.05)["parameter_seed_scatter"]
    Jw = A / scales[:, None]
    estimates = []
    for _ in range(4000):
        mean = A @ np.array([0.4, 0.6]) + rng.normal(0, sigma / math.sqrt(n))
        estimates.append(np.linalg.lstsq(Jw, mean / scales, rcond=None)[0])
    mc = np.std(estimates, axis=0) * 10.0  # parameter = 10 u + 1
    assert predicted["p0"] == pytest.approx(mc[0], rel=0.1)
    assert predicted["p1"] == pytest.approx(mc[1], rel=0.1)


def test_trade_off_is_named_with_its_direction():
    # Both parameters raise both targets in nearly the same ratio: the estimates anti-correlate.
    A = np.array([[1.0, 1.05], [2.0, 2.0]])
    space, problem, best, neighbours = linear_model(A, [0.5, 0.5], np.zeros((2, 2)), [1.0, 2.0], [1.0, 1.0])
    out = calibrate_report.analyse(space, problem, best, neighbours, 0.05)
    assert out["correlation"]["p0"]["p1"] < -0.9
    assert any("p0 and p1 trade off" in s and "raising one while lowering the other" in s for s in out["statements"])
    # Independent columns: no trade-off said.
    space, problem, best, neighbours = linear_model(np.eye(2), [0.5, 0.5], np.zeros((2, 2)), [1.0, 1.0], [1.0, 1.0])
    out = calibrate_report.analyse(space, problem, best, neighbours, 0.05)
    assert out["condition_number"] == pytest.approx(1.0)
    assert not any("trade off" in s for s in out["statements"])


@pytest.mark.parametrize("algorithm", ["bobyqa", "neldermead"])
def test_the_first_point_evaluated_is_the_start_even_near_a_bound(algorithm):
    # friction start 15 in [10, 40] is 1/6 of the range from its bound, less than the default first
    # step (0.25): BOBYQA would move it to 0.25 (17.5 deg) unless the step is cut to the room left.
    import calibrate
    space = Space([{"key": "contact.friction_deg", "min": 10.0, "max": 40.0, "start": 15.0, "log": False},
                   {"key": "contact.eta", "min": 0.05, "max": 1.0, "start": 0.9, "log": False}])

    class Quadratic:
        quiet = True

        def __init__(self):
            self.points = []
            self.history = []

        def evaluate(self, named_points, kind):
            out = []
            for name, u in named_points:
                self.points.append(list(u))
                out.append({"name": name, "objective": (u[0] - 0.4) ** 2 + (u[1] - 0.6) ** 2, "failed": None,
                            "u": list(u), "kind": kind})
            self.history += out
            return out

    ev = Quadratic()
    settings = {"algorithm": algorithm, "max_evaluations": 12, "xtol": 1e-6, "initial_step": 0.25,
                "stop_objective": None, "seed": 1}
    calibrate.optimise(ev, space, settings)
    assert ev.points[0] == pytest.approx(space.start(), abs=1e-12)
    assert space.values(ev.points[0]) == pytest.approx([15.0, 0.9], rel=1e-12)
    # every point inside the bounds
    assert all(0.0 <= x <= 1.0 for p in ev.points for x in p)
