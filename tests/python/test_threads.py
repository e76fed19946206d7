"""A run on a busy machine (issue 15): with fewer free cores than solver.threads, `grainlab run` runs
on the free cores and says so on stderr; GRAINLAB_KEEP_THREADS=1 keeps the requested count. Busy
cores are made by one spinning Python process per core.

The runs that keep 2 threads on busy cores set OMP_WAIT_POLICY=PASSIVE: with libgomp's default
spin-waiting, two OpenMP threads on cores shared with spinning hogs (and CI's other test jobs) meet
at every barrier only when the scheduler happens to run both, which made a 100-sphere run take over
5 minutes on the 2-core CI machine. Passive waiting changes the timing only, never the results."""
import json
import os
import subprocess
import sys
import time

import pytest

from conftest import GRAINLAB, TINY_CONFIG


@pytest.fixture
def busy_cores():
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in os.sched_getaffinity(0)]
    time.sleep(0.5)
    yield
    for h in hogs:
        h.kill()
        h.wait()


def run(tmp_path, name, env=None):
    cfg = tmp_path / "c.toml"
    cfg.write_text(TINY_CONFIG.replace("threads = 1", "threads = 2"))
    return subprocess.run([GRAINLAB, "run", str(cfg), "--out", str(tmp_path / name), "--quiet"],
                          capture_output=True, text=True, timeout=300, env={**os.environ, **(env or {})})


def test_busy_cores_reduce_the_threads_with_a_warning(tmp_path, busy_cores):
    proc = run(tmp_path, "busy")
    assert proc.returncode == 0, proc.stderr
    assert "oversubscribe" in proc.stderr and "using 1 thread" in proc.stderr, proc.stderr
    # The summary keeps the requested count: results do not depend on it.
    assert json.loads((tmp_path / "busy" / "summary.json").read_text())["threads"] == 2


KEEP = {"GRAINLAB_KEEP_THREADS": "1", "OMP_WAIT_POLICY": "PASSIVE"}


def test_keep_threads_only_warns(tmp_path, busy_cores):
    proc = run(tmp_path, "kept", KEEP)
    assert proc.returncode == 0, proc.stderr
    assert "keeping 2 threads as asked" in proc.stderr, proc.stderr


def test_same_results_whatever_the_threads_chosen(tmp_path, busy_cores):
    busy = run(tmp_path, "busy")
    assert "using 1 thread" in busy.stderr
    kept = run(tmp_path, "kept", KEEP)
    assert kept.returncode == 0
    assert (tmp_path / "busy" / "timeseries.csv").read_bytes() == (tmp_path / "kept" / "timeseries.csv").read_bytes()
