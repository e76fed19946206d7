"""Sweeps and calibrations on a Dask cluster (docs/scale-out.md): a scheduler and two worker
processes on 127.0.0.1, started and stopped by the tests. The cluster's table equals the local
sweep's bit for bit (all but the wall time), and a worker killed mid-case makes the case run again
on the other worker, which the table reports."""
import contextlib
import csv
import json
import os
import signal
import socket
import subprocess
import time

import pytest

from conftest import GRAINLAB

pytest.importorskip("distributed")
DATA = os.path.join(os.path.dirname(__file__), "..", "data")
SMALL = os.path.join(DATA, "small-triaxial.toml")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def connected_workers(address):
    from distributed import Client
    with Client(address, timeout=10, set_as_default=False) as client:
        return len(client.scheduler_info()["workers"])


@contextlib.contextmanager
def local_cluster(folder, workers=2):
    """dask-scheduler and `workers` dask-worker processes (one task slot each, no nanny: a killed
    worker stays dead) on 127.0.0.1; everything started here is stopped on exit."""
    folder.mkdir(parents=True, exist_ok=True)
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = []

    def start(name, argv):
        log = open(folder / f"{name}.log", "w")
        procs.append(subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL))
        return procs[-1]

    try:
        start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"])
        deadline = time.time() + 60
        while True:
            with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=1):
                break
            assert time.time() < deadline, (folder / "scheduler.log").read_text()
            time.sleep(0.2)
        worker_procs = [start(f"worker{i}", ["dask-worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                                             "--name", f"w{i}", "--local-directory", str(folder / f"w{i}")])
                        for i in range(workers)]
        while connected_workers(address) < workers:
            assert time.time() < deadline, "workers did not join"
            time.sleep(0.2)
        yield address, worker_procs
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    with local_cluster(tmp_path_factory.mktemp("cluster")) as (address, _):
        yield address


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def without(row, *keys):
    return {k: v for k, v in row.items() if k not in keys}


SWEEP = [SMALL, "--vary", "contact.beta=0,0.15", "--vary", "contact.friction_deg=25,35",
         "--set", "sample.n_particles=100", "--set", "test.final_axial_strain=0.005", "--threads", "1", "--quiet"]


def test_sweep_on_the_cluster_equals_the_local_sweep(grainlab, cluster, tmp_path):
    grainlab("sweep", *SWEEP, "--jobs", "2", "--out", str(tmp_path / "local"), check=0)
    grainlab("sweep", *SWEEP, "--scheduler", cluster, "--out", str(tmp_path / "dask"), check=0)
    local = read_table(tmp_path / "local" / "sweep.csv")
    remote = read_table(tmp_path / "dask" / "sweep.csv")
    assert len(local) == len(remote) == 4
    for a, b in zip(local, remote):
        assert without(a, "wall_seconds") == without(b, "wall_seconds", "attempts", "workers")
        assert b["status"] == "completed" and b["attempts"] == "1" and b["workers"].startswith("tcp://127.0.0.1:")
        # The results came back whole: the time series is byte-identical to the local run's.
        assert (tmp_path / "local" / a["case"] / "timeseries.csv").read_bytes() == \
            (tmp_path / "dask" / b["case"] / "timeseries.csv").read_bytes()
        assert (tmp_path / "dask" / f"{b['case']}.log").exists()
    assert len({r["workers"] for r in remote}) == 2  # both workers took cases
    assert (tmp_path / "dask" / "plots" / "q_eps1.png").exists()


def grainlab_children(pid):
    children = []
    for task in os.listdir(f"/proc/{pid}/task"):
        with contextlib.suppress(OSError), open(f"/proc/{pid}/task/{task}/children") as f:
            children += [int(c) for c in f.read().split()]
    return children


def test_worker_killed_mid_case_reruns_it_elsewhere(grainlab, tmp_path):
    cases = [SMALL, "--vary", "contact.friction_deg=25,30,35", "--set", "sample.n_particles=150",
             "--set", "test.final_axial_strain=0.01", "--threads", "1"]
    grainlab("sweep", *cases, "--jobs", "2", "--quiet", "--out", str(tmp_path / "local"), check=0)
    out = tmp_path / "dask"
    with local_cluster(tmp_path / "cluster") as (address, workers):
        sweep = subprocess.Popen([GRAINLAB, "sweep", *cases, "--scheduler", address, "--shared-out", "--out", str(out)],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # Kill the first worker seen running a case (its grainlab child), mid-case.
        victim, child = None, None
        deadline = time.time() + 300
        while victim is None:
            assert sweep.poll() is None and time.time() < deadline, sweep.communicate()
            for w in workers:
                running = grainlab_children(w.pid)
                if running:
                    victim, child = w, running[0]
                    break
            time.sleep(0.02)
        victim.send_signal(signal.SIGKILL)
        victim.wait()
        stdout, stderr = sweep.communicate(timeout=600)
        assert sweep.returncode == 0, stderr
    # The killed worker's run died with it (no orphan writing into the sweep's folder).
    assert not os.path.exists(f"/proc/{child}") or open(f"/proc/{child}/stat").read().split()[2] == "Z"
    local = read_table(tmp_path / "local" / "sweep.csv")
    remote = read_table(out / "sweep.csv")
    rerun = [r for r in remote if r["attempts"] != "1"]
    assert len(rerun) == 1, remote
    first, second = rerun[0]["workers"].split(" then ")
    assert rerun[0]["attempts"] == "2" and first != second
    assert "after 2 attempts" in stderr
    # Every case, the re-run one included, gives the local sweep's numbers.
    for a, b in zip(local, remote):
        assert b["status"] == "completed"
        assert without(a, "wall_seconds") == without(b, "wall_seconds", "attempts", "workers")
    assert not (out / ".attempts").exists()


def test_calibration_on_the_cluster_equals_the_local_one(grainlab, cluster, tmp_path):
    (tmp_path / "target.toml").write_text("""
[[parameter]]
key = "contact.friction_deg"
min = 20.0
max = 40.0
[[target]]
key = "phi_peak_deg"
value = 30.0
[evaluation]
seeds = [1, 2]
[optimizer]
max_evaluations = 2
[sensitivity]
enabled = false
""")
    config = tmp_path / "config.toml"
    config.write_text(open(SMALL).read().replace("n_particles = 300", "n_particles = 100")
                      .replace("final_axial_strain = 0.05", "final_axial_strain = 0.005"))
    args = ["calibrate", str(config), "--target", str(tmp_path / "target.toml"), "--quiet"]
    grainlab(*args, "--jobs", "2", "--out", str(tmp_path / "local"), check=0)
    grainlab(*args, "--scheduler", cluster, "--out", str(tmp_path / "dask"), check=0)
    with open(tmp_path / "local" / "result.json") as f:
        local = json.load(f)
    with open(tmp_path / "dask" / "result.json") as f:
        remote = json.load(f)
    assert remote["best"] == local["best"] and remote["fit"] == local["fit"]
    with open(tmp_path / "dask" / "runs" / "e0000_seed1.json") as f:
        assert json.load(f)["workers"][0].startswith("tcp://127.0.0.1:")


def test_unreachable_or_malformed_scheduler(grainlab, tmp_path):
    proc = grainlab("sweep", *SWEEP, "--scheduler", "127.0.0.1:8786", "--out", str(tmp_path / "a"), check=2)
    assert "--scheduler" in proc.stderr and "tcp://HOST:PORT" in proc.stderr
    env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="2s")
    proc = subprocess.run([GRAINLAB, "sweep", *SWEEP, "--scheduler", f"tcp://127.0.0.1:{free_port()}",
                           "--out", str(tmp_path / "b")], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 1
    assert "cannot reach the Dask scheduler" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
