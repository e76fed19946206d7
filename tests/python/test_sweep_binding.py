"""Sweep jobs land on distinct cores when OMP_PROC_BIND is exported (issue 25 §4): libgomp binds a
process's first thread to the first OpenMP place, so without OMP_PLACES per job every one-thread
case of a sweep ran on core 0 (four jobs at 0.23x each). Each running case's CPU affinity is read
from /proc while the sweep runs."""
import os
import subprocess
import time

import pytest

from conftest import GRAINLAB, TINY_CONFIG


def children(pid):
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            if int(fields[1]) == pid:
                with open(f"/proc/{entry}/status") as f:
                    allowed = [l.split(":", 1)[1].strip() for l in f if l.startswith("Cpus_allowed_list")]
                out.append((int(entry), allowed[0] if allowed else None))
        except (OSError, IndexError, ValueError):
            continue
    return out


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs two CPUs")
def test_bound_jobs_get_distinct_cpus(tmp_path):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TINY_CONFIG.replace("final_axial_strain = 0.003", "final_axial_strain = 0.02"))
    env = dict(os.environ, OMP_PROC_BIND="true")
    env.pop("OMP_PLACES", None)
    proc = subprocess.Popen([GRAINLAB, "sweep", str(cfg), "--vary", "contact.beta=0,0.1,0.2,0.3", "--jobs", "2",
                             "--threads", "1", "--out", str(tmp_path / "sweep"), "--quiet"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    together = []
    deadline = time.time() + 240
    while proc.poll() is None and time.time() < deadline:
        # Sampled once libgomp has bound the case (at start-up), while two cases run at once.
        kids = [c for c in children(proc.pid) if c[1] is not None]
        if len(kids) == 2:
            time.sleep(0.3)
            again = dict(children(proc.pid))
            if all(pid in again for pid, _ in kids):
                together.append(sorted(again[pid] for pid, _ in kids))
        time.sleep(0.1)
    out, err = proc.communicate(timeout=240)
    assert proc.returncode == 0, err
    assert together, "never saw two cases running at once"
    distinct = [pair for pair in together if pair[0] != pair[1]]
    assert len(distinct) >= 0.8 * len(together), f"cases shared a CPU: {together}"
