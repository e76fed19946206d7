"""What the study tools (e0_study.py, karlsruhe_checks.py, wall_spheroids.py, collapse_servo.py,
eur_study.py) share: whether a run folder holds a completed run, its summary, a queue that runs
`grainlab run` cases a few at a time, and writing a Markdown table."""
import json
import os
import subprocess
import time


def completed(folder):
    """True when folder/summary.json says the run completed."""
    try:
        with open(os.path.join(folder, "summary.json")) as f:
            return json.load(f).get("status") == "completed"
    except (OSError, ValueError):
        return False


def summary(folder):
    """folder/summary.json as a dict."""
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)


def residual_state(summary):
    """(q/p, e) over the residual window (the last 20 % of the test, phi_res's window): the summary's
    residual_q_over_p, residual_void_ratio, or, for a summary written before the critical-state
    criterion existed, the same means it called cs_*. Not a critical state unless
    summary["critical_state_reached"] says so."""
    if "residual_q_over_p" in summary:
        return summary["residual_q_over_p"], summary["residual_void_ratio"]
    return summary.get("cs_q_over_p"), summary.get("cs_void_ratio")


def elastic_nu(value):
    """A Poisson ratio for a table: None (printed null) outside [0, 0.5], where the probe did not
    measure an isotropic elastic response; summaries written since then already say null."""
    return value if value is not None and 0.0 <= value <= 0.5 else None


def positive_modulus(value):
    """A modulus for a table: None (printed null) unless positive (a negative reload secant is a
    sample that kept collapsing through its loop, not a stiffness)."""
    return value if value is not None and value > 0.0 else None


def write_table(path, lines, header=""):
    """Writes the table's lines (after an optional header line) to path and prints them."""
    with open(path, "w") as f:
        f.write(header + "\n".join(lines) + "\n")
    print("\n".join(lines))


def run_cases(exe, preset, cases, jobs, nice=False):
    """Runs `exe run preset --out FOLDER --quiet --threads 1 --set ...` for every (folder, sets) of
    `cases` whose folder is not completed, `jobs` at a time, each logging to FOLDER.log; prints each
    exit status. Every process gets an argument vector."""
    todo = [(folder, sets) for folder, sets in cases if not completed(folder)]
    running = []
    while todo or running:
        while todo and len(running) < jobs:
            folder, sets = todo.pop(0)
            os.makedirs(os.path.dirname(folder) or ".", exist_ok=True)
            argv = (["nice"] if nice else []) + [exe, "run", preset, "--out", folder, "--quiet", "--threads", "1"]
            for s in sets:
                argv += ["--set", s]
            log = open(folder + ".log", "w")
            running.append((folder, subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT), log, time.time()))
            print("started", folder, flush=True)
        time.sleep(2)
        for item in list(running):
            folder, proc, log, t0 = item
            if proc.poll() is not None:
                log.close()
                running.remove(item)
                print(f"{folder}: exit {proc.returncode} after {time.time() - t0:.0f} s", flush=True)
    return 0
