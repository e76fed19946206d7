"""Hostile input to sweeps and calibrations (issue 28, docs/security.md): a key varied twice, a grid
too large to build, a folder that is not theirs, a re-run after a lost case or scheduler, SIGTERM
while cases run. Each is refused with exit 2 and one line naming the key or the folder, or ends
with the table of what finished and one line saying what did not; no case outlives its sweep."""
import contextlib
import csv
import fcntl
import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from conftest import GRAINLAB, TINY_CONFIG

DATA = os.path.join(os.path.dirname(__file__), "..", "data")
CALIBRATE_CONFIG = os.path.join(DATA, "calibrate-small.toml")
CALIBRATE_TARGET = """
[[parameter]]
key = "contact.friction_deg"
min = 20.0
max = 40.0
[[target]]
key = "phi_peak_deg"
value = 41.0
[evaluation]
seeds = [1, 2]
"""


@pytest.fixture
def tiny(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_CONFIG)
    return str(path)


def one_line(proc_or_text):
    text = proc_or_text if isinstance(proc_or_text, str) else proc_or_text.stderr
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    return lines[0]


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def processes_mentioning(text):
    """Pids of the processes whose command line mentions text (a folder of this test)."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        with contextlib.suppress(OSError):
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                cmdline = f.read().decode(errors="replace")
            with open(f"/proc/{pid}/stat") as f:
                state = f.read().rsplit(")", 1)[1].split()[0]
            if text in cmdline and state != "Z":
                found.append(int(pid))
    return found


def snapshot(folder):
    """Every file under folder with its size and modification time."""
    out = {}
    for root, _, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            with contextlib.suppress(OSError):
                st = os.stat(path)
                out[path] = (st.st_size, st.st_mtime_ns)
    return out


def assert_nothing_left(folder, outlived, still_writing):
    """No process names `folder` within 5 s, and nothing changes in it for 1.5 s after that."""
    for _ in range(100):
        if not processes_mentioning(str(folder)):
            break
        time.sleep(0.05)
    assert not processes_mentioning(str(folder)), outlived
    before = snapshot(folder)
    time.sleep(1.5)
    assert snapshot(folder) == before, still_writing


# ---- 1. the grid's keys and values -------------------------------------------------------------

@pytest.mark.parametrize("args, words", [
    (["--vary", "contact.beta=0,1", "--vary", "contact.beta=0.5,2"], ["contact.beta", "varied twice"]),
    (["--vary", "contact.beta=0,1", "--set", "contact.beta=0.3"], ["--set contact.beta=0.3", "also varied"]),
    (["--vary", "sample.grading.d_max=6e-3,7e-3", "--set", "sample.grading.d_max=5e-3"], ["d_max", "also varied"]),
    (["--vary", 'sample.grading={type="uniform",d_min=4e-3,d_max=6e-3},{type="uniform",d_min=4e-3,d_max=7e-3}',
      "--set", "sample.grading.d_min=3e-3"], ["sample.grading", "also varied"]),
    (["--vary", 'sample.grading={type="uniform",d_min=4e-3,d_max=6e-3},{type="uniform",d_min=4e-3,d_max=7e-3}',
      "--vary", "sample.grading.d_max=6e-3,8e-3"], ["sample.grading.d_max", "inside sample.grading"]),
    (["--vary", "contact.beta=0,1,0"], ["contact.beta", "0", "given twice"]),
    (["--vary", "contact.beta=0, 1,1 "], ["contact.beta", "1", "given twice"]),
    (["--vary", "contact.beta=0,0.0"], ["contact.beta", "0.0", "same config"]),
    (["--vary", "contact.beta=0,1", "--jobs", "100000"], ["--jobs", "100000", "1024"]),
])
def test_grid_keys_and_values_are_checked(grainlab, tiny, tmp_path, args, words):
    out = tmp_path / "sweep"
    proc = grainlab("sweep", tiny, *args, "--out", str(out), check=2)
    line = one_line(proc)
    for w in words:
        assert w in line, line
    assert not out.exists()


def test_a_grid_of_1e10_cases_is_refused_before_it_is_built(grainlab, tiny, tmp_path):
    vary = []
    for i in range(10):
        vary += ["--vary", f"contact.beta{i}=" + ",".join(str(v) for v in range(10))]
    t0 = time.time()
    proc = grainlab("sweep", tiny, *vary, "--out", str(tmp_path / "s"), check=2, timeout=30)
    assert time.time() - t0 < 10
    line = one_line(proc)
    assert "1e+10 cases" in line and "limit is 10000" in line
    assert not (tmp_path / "s").exists()
    # At the limit the grid is accepted as far as its keys (here: unknown, refused by the config check).
    proc = grainlab("sweep", tiny, "--vary", "contact.nope=" + ",".join(str(v) for v in range(10001)),
                    "--out", str(tmp_path / "s"), check=2)
    assert "10001 cases" in one_line(proc)


# ---- 3. folders that are not theirs ------------------------------------------------------------

SMALL_SWEEP = ["--vary", "contact.beta=0,0.15", "--threads", "1", "--quiet"]


def test_sweep_and_calibrate_refuse_a_folder_that_is_not_theirs(grainlab, tiny, tmp_path):
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine\n")
    (foreign / "report.md").write_text("my report\n")
    (foreign / "sweep.csv").write_text("my,table\n")
    before = snapshot(foreign)
    line = one_line(grainlab("sweep", tiny, *SMALL_SWEEP, "--out", str(foreign), check=2))
    assert str(foreign) in line and "no sweep.json" in line
    target = tmp_path / "target.toml"
    target.write_text(CALIBRATE_TARGET)
    line = one_line(grainlab("calibrate", CALIBRATE_CONFIG, "--target", str(target), "--out", str(foreign), check=2))
    assert str(foreign) in line and "no calibration.json" in line
    assert snapshot(foreign) == before
    # A run's results folder and a calibration's folder are not a sweep's either, and the reverse.
    run = tmp_path / "run"
    grainlab("run", tiny, "--out", str(run), "--quiet", check=0)
    before = snapshot(run)
    assert "no sweep.json" in one_line(grainlab("sweep", tiny, *SMALL_SWEEP, "--out", str(run), check=2))
    assert "no calibration.json" in one_line(
        grainlab("calibrate", CALIBRATE_CONFIG, "--target", str(target), "--out", str(run), check=2))
    assert snapshot(run) == before
    fake_calibration = tmp_path / "calibration"
    fake_calibration.mkdir()
    (fake_calibration / "calibration.json").write_text("{}")
    assert "no sweep.json" in one_line(grainlab("sweep", tiny, *SMALL_SWEEP, "--out", str(fake_calibration), check=2))
    # A file where the folder should be: exit 1 naming it.
    (tmp_path / "file").write_text("x")
    proc = grainlab("sweep", tiny, *SMALL_SWEEP, "--out", str(tmp_path / "file"), check=1)
    assert str(tmp_path / "file") in one_line(proc)


def test_a_folder_in_use_by_another_sweep_or_calibration_is_refused(grainlab, tiny, tmp_path):
    for command, folder_args in (("sweep", [tiny, *SMALL_SWEEP]),
                                 ("calibrate", [CALIBRATE_CONFIG, "--target", str(tmp_path / "target.toml")])):
        (tmp_path / "target.toml").write_text(CALIBRATE_TARGET)
        busy = tmp_path / f"busy-{command}"
        busy.mkdir()
        fd = os.open(busy, os.O_RDONLY | os.O_DIRECTORY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)  # what a running sweep or calibration holds
            line = one_line(grainlab(command, *folder_args, "--out", str(busy), check=2))
            assert str(busy) in line and "another grainlab" in line
        finally:
            os.close(fd)
        assert os.listdir(busy) == []


# ---- 4. resuming a sweep -----------------------------------------------------------------------

def test_rerun_keeps_finished_cases_and_reruns_the_others(grainlab, tiny, tmp_path):
    out = tmp_path / "sweep"
    args = ["sweep", tiny, "--vary", "contact.beta=0,0.15,0.3", "--threads", "1", "--jobs", "2", "--out", str(out)]
    grainlab(*args, "--quiet", check=0)
    first = read_table(out / "sweep.csv")
    names = [r["case"] for r in first]
    assert json.loads((out / "sweep.json").read_text())["cases"] == names
    # Case 1 did not complete (as after a kill), case 2 ran another config (an earlier config file).
    os.remove(out / names[1] / "summary.json")
    resolved = out / names[2] / "config.resolved.toml"
    text = resolved.read_text()
    assert len(re.findall(r"(?m)^e0 = ", text)) == 1
    resolved.write_text(re.sub(r"(?m)^e0 = .*$", "e0 = 0.75", text))
    kept = os.stat(out / names[0] / "timeseries.csv")
    proc = grainlab(*args, "--quiet", check=0)
    assert proc.stderr == ""
    again = read_table(out / "sweep.csv")
    assert [r["status"] for r in again] == ["completed"] * 3
    # Case 0 was kept (not run again), the other two ran again, to the same values.
    assert os.stat(out / names[0] / "timeseries.csv").st_mtime_ns == kept.st_mtime_ns
    assert os.stat(out / names[1] / "timeseries.csv").st_mtime_ns > kept.st_mtime_ns
    assert os.stat(out / names[2] / "timeseries.csv").st_mtime_ns > kept.st_mtime_ns
    assert "e0 = 0.75" not in resolved.read_text()
    assert [{k: v for k, v in r.items() if k != "wall_seconds"} for r in again] == \
        [{k: v for k, v in r.items() if k != "wall_seconds"} for r in first]
    # Without --quiet the sweep says what it kept.
    proc = grainlab(*args, check=0)
    assert "3 of 3 cases completed earlier" in proc.stderr
    # A changed config (here by --set) runs every case again.
    proc = grainlab(*args, "--set", "test.final_axial_strain=0.002", check=0)
    assert "kept" not in proc.stderr and proc.stderr.count("completed") == 3
    # Another grid is refused in this folder, naming the grid it holds.
    line = one_line(grainlab("sweep", tiny, "--vary", "contact.beta=0,0.2", "--out", str(out), check=2))
    assert str(out) in line and "another grid" in line and "contact.beta=0,0.15,0.3" in line


def test_failed_cases_leave_the_table_and_one_line(grainlab, tiny, tmp_path):
    out = tmp_path / "sweep"
    # 4e-6 s forced far above the critical step: that case blows up (exit 1).
    proc = grainlab("sweep", tiny, "--vary", "solver.dt=1e-7,4e-6", "--set", "solver.force_dt=true",
                    "--set", "sample.prep_friction_deg=10.0", "--threads", "1", "--out", str(out), "--quiet", check=1)
    line = one_line(proc)
    assert "1 of 2 cases completed, 1 failed" in line and "sweep.csv" in line and "Traceback" not in proc.stderr
    assert [r["status"] for r in read_table(out / "sweep.csv")] == ["completed", "failed (exit 1)"]


# ---- 5. SIGTERM, SIGINT and SIGKILL to a local sweep ---------------------------------------------

def start_long_sweep(tiny, out):
    # Cases of a few tens of seconds each, two at once: the sweep is stopped while they run.
    return subprocess.Popen([GRAINLAB, "sweep", tiny, "--vary", "contact.beta=0,0.1,0.2", "--set",
                             "sample.n_particles=200", "--set", "test.final_axial_strain=0.2", "--threads", "1",
                             "--jobs", "2", "--out", str(out), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for_cases(sweep, out, count):
    deadline = time.time() + 60
    while len(processes_mentioning(str(out) + "/case")) < count or \
            len([p for p in out.glob("case*") if (p / "config.resolved.toml").exists()]) < count:
        assert sweep.poll() is None and time.time() < deadline, sweep.communicate()
        time.sleep(0.05)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL], ids=["SIGTERM", "SIGINT", "SIGKILL"])
def test_stopped_sweep_leaves_no_case_running(tiny, tmp_path, sig):
    out = tmp_path / "sweep"
    sweep = start_long_sweep(tiny, out)
    wait_for_cases(sweep, out, 2)
    sweep.send_signal(sig)
    stdout, stderr = sweep.communicate(timeout=60)
    assert sweep.returncode == (-signal.SIGKILL if sig == signal.SIGKILL else 128 + sig), stderr
    assert_nothing_left(out, "a case outlived its sweep", "something still writes into the sweep's folder")
    if sig != signal.SIGKILL:
        assert stderr.count("\n") == 1 and f"interrupted by {signal.Signals(sig).name}" in stderr, stderr
        assert "0 of 3 cases completed, 2 stopped, 1 not run" in stderr
        rows = read_table(out / "sweep.csv")
        assert [r["status"] for r in rows] == [f"stopped ({signal.Signals(sig).name})"] * 2 + ["not run"]


# ---- 4. Dask: the scheduler lost mid-sweep -------------------------------------------------------

def test_lost_scheduler_leaves_the_table_and_a_rerun_keeps_the_finished_cases(tiny, tmp_path):
    pytest.importorskip("distributed")
    from test_dask import local_cluster
    out = tmp_path / "sweep"
    args = [GRAINLAB, "sweep", tiny, "--vary", "contact.beta=0,0.05,0.1,0.15", "--set", "sample.n_particles=150",
            "--set", "test.final_axial_strain=0.01", "--threads", "1", "--out", str(out), "--quiet"]
    env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="5s")
    with local_cluster(tmp_path / "cluster", workers=1) as (address, _):
        sweep = subprocess.Popen([*args, "--scheduler", address], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True, env=env)
        # The scheduler dies once the first case has come back.
        deadline = time.time() + 300
        while not list(out.glob("case*.log")):
            assert sweep.poll() is None and time.time() < deadline, sweep.communicate()
            time.sleep(0.05)
        scheduler = [p for p in processes_mentioning(address.rsplit(":", 1)[1]) if b"dask-scheduler" in
                     open(f"/proc/{p}/cmdline", "rb").read()]
        assert len(scheduler) == 1
        os.kill(scheduler[0], signal.SIGKILL)
        stdout, stderr = sweep.communicate(timeout=300)
    assert sweep.returncode == 1, stderr
    line = one_line(stderr)
    assert "Traceback" not in stderr and "was lost" in line and "not run" in line and "sweep.csv" in line
    rows = read_table(out / "sweep.csv")
    done = [r["case"] for r in rows if r["status"] == "completed"]
    assert 1 <= len(done) < 4 and all(r["status"] in ("completed", "not run") for r in rows)
    kept = {name: os.stat(out / name / "timeseries.csv").st_mtime_ns for name in done}
    # The same command (here without the lost cluster: locally) keeps what finished and runs the rest.
    proc = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert [r["status"] for r in read_table(out / "sweep.csv")] == ["completed"] * 4
    assert {name: os.stat(out / name / "timeseries.csv").st_mtime_ns for name in done} == kept


def test_sigterm_to_a_dask_sweep_ends_it_with_its_table(tiny, tmp_path):
    pytest.importorskip("distributed")
    from test_dask import local_cluster
    out = tmp_path / "sweep"
    with local_cluster(tmp_path / "cluster", workers=1) as (address, workers):
        sweep = subprocess.Popen([GRAINLAB, "sweep", tiny, "--vary", "contact.beta=0,0.1", "--set",
                                  "sample.n_particles=200", "--set", "test.final_axial_strain=0.2", "--threads", "1",
                                  "--scheduler", address, "--out", str(out), "--quiet"],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 120
        while not processes_mentioning("grainlab-"):  # the worker's run (in its scratch folder)
            assert sweep.poll() is None and time.time() < deadline, sweep.communicate()
            time.sleep(0.05)
        sweep.send_signal(signal.SIGTERM)
        _, stderr = sweep.communicate(timeout=60)
    assert sweep.returncode == 143, stderr
    line = one_line(stderr)
    assert "interrupted" in line and "SIGTERM" in line and "0 of 2 cases completed, 2 not run" in line
    assert [r["status"] for r in read_table(out / "sweep.csv")] == ["not run", "not run"]
    assert not processes_mentioning(str(out))


# ---- the calibration runner ----------------------------------------------------------------------

def test_sigterm_to_a_calibration_leaves_no_run(grainlab, tmp_path):
    config = tmp_path / "config.toml"
    with open(CALIBRATE_CONFIG) as f:
        config.write_text(f.read().replace("final_axial_strain = 0.02", "final_axial_strain = 0.2"))
    target = tmp_path / "target.toml"
    target.write_text(CALIBRATE_TARGET + "[optimizer]\nmax_evaluations = 2\n[sensitivity]\nenabled = false\n")
    folder = tmp_path / "calibration"
    proc = subprocess.Popen([GRAINLAB, "calibrate", str(config), "--target", str(target), "--jobs", "2", "--out",
                             str(folder), "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while len(processes_mentioning(str(folder / "runs"))) < 2:
        assert proc.poll() is None and time.time() < deadline, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143, stderr
    assert "interrupted (SIGTERM)" in stderr and "resumes" in stderr and "Traceback" not in stderr
    assert_nothing_left(folder, "a run outlived the calibration", "something still writes into the calibration's folder")


# ---- 6. empty values ---------------------------------------------------------------------------

def test_an_empty_scheduler_in_the_target_file_is_refused(grainlab, tmp_path):
    target = tmp_path / "target.toml"
    target.write_text(CALIBRATE_TARGET + '[execution]\nscheduler = ""\n')
    line = one_line(grainlab("calibrate", CALIBRATE_CONFIG, "--target", str(target), "--out", str(tmp_path / "c"),
                             check=2))
    assert "execution.scheduler" in line and "empty" in line and "tcp://HOST:PORT" in line
    assert not (tmp_path / "c").exists()


def test_python_sweep_refuses_an_empty_out(tiny, tmp_path):
    code = ("import grainlab, sys\n"
            "try:\n"
            f"    grainlab.sweep({tiny!r}, vary={{'contact.beta': [0, 0.15]}}, out='')\n"
            "except grainlab.ConfigError as e:\n"
            "    print('ConfigError:', e); sys.exit(3)\n")
    python_dir = os.path.join(os.path.dirname(os.path.abspath(GRAINLAB)), "python")
    if not os.path.isdir(os.path.join(python_dir, "grainlab")):
        pytest.skip("the Python module is not built")
    env = dict(os.environ, PYTHONPATH=python_dir, GRAINLAB_BIN=os.path.abspath(GRAINLAB))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120,
                          env=env)
    assert proc.returncode == 3, proc.stdout + proc.stderr
    assert "out" in proc.stdout and "empty" in proc.stdout
    assert not (tmp_path / "runs").exists()
