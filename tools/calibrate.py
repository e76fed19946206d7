#!/usr/bin/env python3
"""Calibration driver of `grainlab calibrate` (docs/calibration.md).

Started by `grainlab calibrate CONFIG --target TARGET.toml`, which validated both and wrote
FOLDER/calibration.json (the inputs, defaults filled in). This driver:

  1. minimises the objective (calibrate_objective.py) over the free parameters with an NLopt
     derivative-free algorithm; each evaluation is one `grainlab run` per seed, run in parallel
     (LocalRunner: --jobs processes; DaskRunner: a cluster), with the parameters as --set overrides;
  2. evaluates finite-difference neighbours of the best point, all at once, for the sensitivities;
  3. writes result.json, report.md, best.toml (the config with the calibrated values) and plots.

Resuming: every run's outcome is stored as it completes (runs/NAME.json beside its folder
runs/NAME/). The NLopt algorithms are deterministic (the stochastic one is seeded), so a restarted
calibration replays the same sequence of points: completed runs are read back instead of run
again, and the calibration reaches the same result as one that was never interrupted.

Usage (by grainlab): calibrate.py --folder DIR --grainlab EXE --jobs N [--threads T]
                                  [--scheduler tcp://HOST:PORT] [--quiet]"""
import argparse
import json
import os
import shutil
import sys
import time

import nlopt

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calibrate_report  # noqa: E402
from calibrate_objective import InputProblem, Problem, Space, seed_statistics  # noqa: E402
from dask_runner import DaskRunner, LocalRunner, Stopped, stop_on_signals  # noqa: E402

ALGORITHMS = {"bobyqa": nlopt.LN_BOBYQA, "cobyla": nlopt.LN_COBYLA, "neldermead": nlopt.LN_NELDERMEAD,
              "sbplx": nlopt.LN_SBPLX, "direct": nlopt.GN_DIRECT_L, "crs2": nlopt.GN_CRS2_LM}
# Outputs a calibration does not read: no plots, snapshots or checkpoints per run (they do not change
# the physics: the same time series with and without them).
RUN_OUTPUT_SETS = ["output.plots=false", "output.vtk_every_strain=0", "output.checkpoint_every=0"]
# An evaluation that could not be measured (a run failed, a target was null) gets this multiple of
# the worst objective so far: finite, so that model-based optimisers stay well defined, and worse
# than anything measured, so that they move away from it.
FAILURE_PENALTY = 10.0


class CalibrationError(Exception):
    """Stops the calibration (exit 1) with a message."""


def write_json_atomic(path, data):
    tmp = f"{path}.tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


class RunStore:
    """The runs of the calibration folder: runs/NAME/ (results) and runs/NAME.json (outcome)."""

    def __init__(self, folder, problem):
        self.dir = os.path.join(folder, "runs")
        os.makedirs(self.dir, exist_ok=True)
        self.problem = problem
        self.records = {}
        for entry in sorted(os.listdir(self.dir)):
            if entry.endswith(".json"):
                with open(os.path.join(self.dir, entry)) as f:
                    record = json.load(f)
                self.records[record["name"]] = record

    def lookup(self, name, sets, seed):
        record = self.records.get(name)
        if record is None:
            return None
        if record["sets"] != sets or record["seed"] != seed:
            raise CalibrationError(f"runs/{name}.json holds another run ({record['sets']}, seed {record['seed']}) "
                                   f"than the replay asks for ({sets}, seed {seed}): the calibration folder "
                                   "does not belong to this sequence; use a new --out")
        return record

    def record(self, job, result):
        """Stores a finished run's outcome (called as each run completes)."""
        run_dir = job["out"]
        with open(os.path.join(self.dir, job["name"] + ".log"), "w") as f:
            f.write(result["log"])
        code = result["exit_code"]
        if code == 2:
            last = result["log"].strip().splitlines()[-1:] or ["(no message)"]
            raise InputProblem(f"run {job['name']} rejected its input: {last[0]}")
        if code not in (0, 1):
            raise CalibrationError(f"run {job['name']} ended with exit code {code} (killed?); see runs/{job['name']}.log; "
                                   "rerun the same command to resume")
        values, curves, problem = {}, {}, None
        summary = {}
        if os.path.exists(os.path.join(run_dir, "summary.json")):
            with open(os.path.join(run_dir, "summary.json")) as f:
                summary = json.load(f)
        if code == 0 and summary.get("status") == "completed":
            values, curves, problem = self.problem.outputs(run_dir, summary, job["condition"])
        else:
            problem = f"run failed (exit {code}): {summary.get('error', 'see the log')}"
        record = {"name": job["name"], "sets": job["param_sets"], "seed": job["seed"], "exit_code": code,
                  "attempts": result["attempts"], "workers": result["workers"], "started": result.get("started"),
                  "finished": result.get("finished"), "wall_seconds": summary.get("wall_seconds"),
                  "values": values, "curves": curves, "problem": problem}
        write_json_atomic(os.path.join(self.dir, job["name"] + ".json"), record)
        self.records[job["name"]] = record


class Evaluator:
    """Evaluates points (one run per seed), reusing stored runs, and keeps the history."""

    def __init__(self, folder, inputs, args, space, problem, runner):
        self.folder = folder
        self.space = space
        self.problem = problem
        self.runner = runner
        self.seeds = inputs["target"]["seeds"]
        self.quiet = args.quiet
        self.store = RunStore(folder, problem)
        config = inputs["config"]
        config_text = None
        if not config.startswith("preset:"):
            with open(config) as f:
                config_text = f.read()
        self.job_base = {"executable": args.grainlab, "config": config, "config_text": config_text,
                         "threads": args.threads}
        self.history = []
        self.runs_started = 0
        # The evaluation log is rebuilt by the replay on every start.
        self.log_path = os.path.join(folder, "evaluations.jsonl")
        open(self.log_path, "w").close()

    def evaluate(self, points, kind):
        """points: [(name, u)]. Runs what is missing, all at once, and returns their evaluations."""
        missing = []
        stored = {}
        for name, u in points:
            stored[name] = 0
            for condition in self.problem.conditions:
                param_sets = self.space.sets(u) + condition["sets"]
                for seed in self.seeds:
                    run = self.run_name(name, condition, seed)
                    if self.store.lookup(run, param_sets, seed) is None:
                        out = os.path.join(self.store.dir, run)
                        missing.append(dict(self.job_base, name=run, out=out, seed=seed, param_sets=param_sets,
                                            condition=condition["id"],
                                            sets=param_sets + [f"sample.seed={seed}"] + RUN_OUTPUT_SETS))
                    else:
                        stored[name] += 1
        if missing:
            for job in missing:  # a folder left by an interrupted run is never mixed with a new one
                if os.path.exists(job["out"]):
                    shutil.rmtree(job["out"])
            self.runs_started += len(missing)
            self.runner.run(missing, self.store.record)
        return [self._assemble(name, u, kind, stored[name]) for name, u in points]

    @staticmethod
    def run_name(name, condition, seed):
        """e0003_seed2, or e0003_p100kPa_seed2 with several conditions (pressures)."""
        return f"{name}_{condition['id']}_seed{seed}" if condition["id"] else f"{name}_seed{seed}"

    def _assemble(self, name, u, kind, cached):
        # One record per seed: the runs of every condition of that seed, merged (their targets and
        # curves are disjoint), so that seed means and scatter are over the seeds as before.
        per_condition = [[self.store.records[self.run_name(name, c, seed)] for c in self.problem.conditions]
                         for seed in self.seeds]
        records = [{"name": "+".join(r["name"] for r in runs),
                    "problem": next((r["problem"] for r in runs if r["problem"]), None),
                    "values": {k: v for r in runs for k, v in r["values"].items()},
                    "curves": {k: v for r in runs for k, v in r["curves"].items()}} for runs in per_condition]
        problems = [r["problem"] for r in records if r["problem"]]
        evaluation = {"index": len(self.history), "name": name, "kind": kind, "u": [float(x) for x in u],
                      "parameters": dict(zip(self.space.keys, self.space.values(u))), "seeds": self.seeds,
                      "runs": [r["name"] for runs in per_condition for r in runs], "failed": problems[0] if problems else None,
                      "objective": None, "objective_per_seed": None, "values": {}, "curves": {}}
        if not problems:
            per_seed_y = [self.problem.output_vector(r["values"], r["curves"]) for r in records]
            evaluation["per_seed_outputs"] = per_seed_y
            values = {t["key"]: [r["values"][t["key"]] for r in records] for t in self.problem.targets}
            for key, vs in values.items():
                mean, std = seed_statistics(vs)
                evaluation["values"][key] = {"mean": float(mean), "std": None if std is None else float(std),
                                             "per_seed": vs}
            for q in self.problem.quantities():
                mean, std = seed_statistics([r["curves"][q] for r in records])
                evaluation["curves"][q] = {"mean": mean.tolist(), "std": None if std is None else std.tolist()}
            mean_values = {k: v["mean"] for k, v in evaluation["values"].items()}
            mean_curves = {q: c["mean"] for q, c in evaluation["curves"].items()}
            evaluation["objective"] = self.problem.objective(mean_values, mean_curves)
            evaluation["objective_per_seed"] = [self.problem.objective(r["values"], r["curves"]) for r in records]
        else:
            finite = [e["objective"] for e in self.history if e["failed"] is None]
            evaluation["objective"] = FAILURE_PENALTY * max([1.0] + finite)
        self.history.append(evaluation)
        with open(self.log_path, "a") as f:
            f.write(json.dumps({k: v for k, v in evaluation.items() if k != "per_seed_outputs"}) + "\n")
        if not self.quiet:
            params = ", ".join(f"{k.split('.')[-1]}={v:.6g}" for k, v in evaluation["parameters"].items())
            state = f"FAILED ({evaluation['failed']}), penalty {evaluation['objective']:.4g}" if problems \
                else f"objective {evaluation['objective']:.6g}"
            reused = f" [{cached}/{len(self.seeds) * len(self.problem.conditions)} runs stored]" if cached else ""
            print(f"{name} ({kind}): {params} -> {state}{reused}", file=sys.stderr, flush=True)
        return evaluation


def optimise(evaluator, space, settings):
    """Runs the NLopt algorithm to its budget; returns (the best evaluation, NLopt's stop reason)."""
    n = len(space)
    opt = nlopt.opt(ALGORITHMS[settings["algorithm"]], n)
    if settings["algorithm"] == "crs2":
        nlopt.srand(settings["seed"])  # its random population, fixed so that a resume replays it
    opt.set_lower_bounds([0.0] * n)
    opt.set_upper_bounds([1.0] * n)
    opt.set_maxeval(settings["max_evaluations"])
    opt.set_xtol_abs(settings["xtol"])
    # BOBYQA needs its first steps inside the bounds and silently moves a start nearer a bound than
    # the step; so the step of such a parameter is cut to its distance from the bound, and the
    # first point evaluated is the start the user gave. A start on a bound is moved (said so).
    start = space.start()
    steps = []
    for j, u in enumerate(start):
        room = min(u, 1.0 - u)
        steps.append(min(settings["initial_step"], room) if room >= 0.01 else settings["initial_step"])
        if room < 0.01 and settings["algorithm"] == "bobyqa" and not getattr(evaluator, "quiet", False):
            print(f"calibrate: parameter {j + 1}'s start is on its bound; bobyqa starts "
                  f"{settings['initial_step']:g} of its range inside", file=sys.stderr, flush=True)
    opt.set_initial_step(steps)
    if settings["stop_objective"] is not None:
        opt.set_stopval(settings["stop_objective"])
    counter = [0]

    def objective(u, grad):
        # NLopt may ask beyond max_evaluations with population methods; the budget is ours to keep.
        if counter[0] >= settings["max_evaluations"]:
            raise nlopt.ForcedStop
        name = f"e{counter[0]:04d}"
        counter[0] += 1
        return evaluator.evaluate([(name, list(u))], "optimizer")[0]["objective"]

    opt.set_min_objective(objective)
    reason = "maximum evaluations reached"
    try:
        opt.optimize(start)
        reason = {nlopt.SUCCESS: "converged", nlopt.STOPVAL_REACHED: "stop_objective reached",
                  nlopt.FTOL_REACHED: "objective tolerance reached", nlopt.XTOL_REACHED: "xtol reached",
                  nlopt.MAXEVAL_REACHED: "maximum evaluations reached"}.get(opt.last_optimize_result(), "stopped")
    except nlopt.RoundoffLimited:
        reason = "limited by round-off (the objective's noise)"
    except nlopt.ForcedStop:
        reason = "maximum evaluations reached"
    measured = [e for e in evaluator.history if e["kind"] == "optimizer" and e["failed"] is None]
    if not measured:
        raise CalibrationError("every evaluation failed; see runs/*.log and the 'failed' entries of evaluations.jsonl")
    return min(measured, key=lambda e: e["objective"]), reason


def sensitivity_points(best, step):
    """Central differences in unit coordinates, one-sided at a bound (the best point is the other side)."""
    points = []
    for j in range(len(best["u"])):
        u = best["u"][j]
        for sign, label in ((1, "plus"), (-1, "minus")):
            v = u + sign * step
            if 0.0 <= v <= 1.0:
                point = list(best["u"])
                point[j] = v
                points.append((j, label, point))
    return points


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--folder", required=True)
    parser.add_argument("--grainlab", required=True)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--scheduler", default="")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args()
    # SIGTERM and SIGHUP stop it as Ctrl-C does: the runs in progress are ended, what completed is kept.
    stop_on_signals()
    folder = args.folder
    with open(os.path.join(folder, "calibration.json")) as f:
        inputs = json.load(f)
    target = inputs["target"]
    space = Space(target["parameters"])
    problem = Problem(target)
    t0 = time.time()
    try:
        runner = DaskRunner(args.scheduler, quiet=args.quiet) if args.scheduler else LocalRunner(args.jobs)
    except ConnectionError as e:
        print(f"grainlab: calibrate: {e}", file=sys.stderr)
        return 1
    try:
        evaluator = Evaluator(folder, inputs, args, space, problem, runner)
        best, reason = optimise(evaluator, space, target["optimizer"])
        neighbours = []
        if target["sensitivity"]["enabled"]:
            points = sensitivity_points(best, target["sensitivity"]["step"])
            evaluations = evaluator.evaluate([(f"sens{j + 1}_{label}", u) for j, label, u in points], "sensitivity")
            neighbours = [(j, e) for (j, _, _), e in zip(points, evaluations)]
        calibrate_report.write(folder, inputs, space, problem, evaluator.history, best, neighbours,
                               {"stop_reason": reason, "runs_started_this_session": evaluator.runs_started,
                                "seconds_this_session": time.time() - t0, "grainlab": args.grainlab})
    except InputProblem as e:
        print(f"grainlab: {e}", file=sys.stderr)
        return 2
    except CalibrationError as e:
        print(f"grainlab: calibrate: {e}", file=sys.stderr)
        return 1
    except ConnectionError as e:  # the scheduler went away mid-way (dask_runner.ClusterLost)
        print(f"grainlab: calibrate: {e}; the runs that completed are kept: the same command resumes from {folder}",
              file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"grainlab: calibrate: interrupted; the same command resumes from {folder}", file=sys.stderr)
        return 130
    except Stopped as e:
        print(f"grainlab: calibrate: interrupted ({e}); the same command resumes from {folder}", file=sys.stderr)
        return 143
    finally:
        runner.close()
    if not args.quiet:
        params = ", ".join(f"{k} = {v:.6g}" for k, v in best["parameters"].items())
        print(f"best ({best['name']}, objective {best['objective']:.6g}; {reason}): {params}\n"
              f"report in {os.path.join(folder, 'report.md')}, config in {os.path.join(folder, 'best.toml')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
