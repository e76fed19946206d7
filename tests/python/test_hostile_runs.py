"""Issue 28 (hostile-input audit, third round): the run, its results folder, resume and the Python
module. Each test reproduces one reported defect and checks it is refused (exit 2 naming the key or
file) or works; none may end in a signal, a hang or a silent wrong value. Small runs (100 spheres,
one thread)."""
import json
import multiprocessing
import os
import shutil
import subprocess
import sys
import threading
import time

import pytest

from conftest import GRAINLAB, TINY_CONFIG as TINY, kill_after_second_checkpoint

BUILD = os.path.dirname(os.path.abspath(GRAINLAB))
sys.path.insert(0, os.path.join(BUILD, "python"))


def run(args, timeout=300, **kw):
    return subprocess.run([GRAINLAB, *args], capture_output=True, text=True, timeout=timeout, **kw)


def one_line(proc):
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    return lines[0]


def write(path, text):
    path.write_text(text)
    return str(path)


def killed_during_shear(cfg, folder, extra=()):
    """Starts a run and kills it (SIGKILL) once its second checkpoint is written."""
    proc = subprocess.Popen([GRAINLAB, "run", cfg, "--out", str(folder), "--quiet", *extra])
    kill_after_second_checkpoint(proc, folder / "checkpoint" / "state.bin")
    assert not (folder / "summary.json").exists()


LONGER = TINY.replace("final_axial_strain = 0.003", "final_axial_strain = 0.01").replace(
    "plots = false", "plots = false\nsave_packing = true")


# --- crashes --------------------------------------------------------------------------------------

def test_bench_thread_count_is_bounded():
    proc = run(["bench", "--threads", "100000", "--particles", "100", "--steps", "10"])
    assert proc.returncode == 2, proc.stderr
    line = one_line(proc)
    assert "--threads" in line and "100000" in line and "1024" in line
    for cmd in (["run", "preset:quick-triaxial"], ["sweep", "preset:quick-triaxial", "--vary", "contact.beta=0,1"]):
        proc = run([*cmd, "--threads", "5000"])
        assert proc.returncode == 2 and "1024" in one_line(proc)


def test_sparse_huge_checkpoint_is_refused_before_it_is_read(tmp_path):
    cfg = write(tmp_path / "c.toml", LONGER)
    folder = tmp_path / "run"
    killed_during_shear(cfg, folder)
    state = folder / "checkpoint" / "state.bin"
    good = state.read_bytes()
    # A sparse file of 32 GiB less a byte whose header claims it all (magic and sizes consistent).
    size = (32 << 30) - 1
    with open(state, "wb") as f:
        header = bytearray(good[:80])
        body = size - 80 - 8
        header[64:72] = (16).to_bytes(8, "little")
        header[72:80] = (body - 16).to_bytes(8, "little")
        f.write(header)
        f.truncate(size)
    t0 = time.time()
    proc = run(["resume", str(folder), "--quiet"], timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert "state.bin" in one_line(proc) and "memory" in one_line(proc)
    assert time.time() - t0 < 20  # refused from the header, not after reading 32 GiB
    state.write_bytes(good)
    proc = run(["resume", str(folder), "--quiet"])
    assert proc.returncode == 0, proc.stderr


# --- empty values ---------------------------------------------------------------------------------

@pytest.mark.parametrize("args", [
    ["run", "CFG", "--out", ""],
    ["run", ""],
    ["check", ""],
    ["resume", ""],
    ["sweep", "CFG", "--vary", "contact.beta=0,1", "--out", ""],
    ["sweep", "CFG", "--vary", "contact.beta=0,1", "--scheduler", ""],
    ["calibrate", "CFG", "--target", "", "--out", "x"],
    ["calibrate", "CFG", "--target", "t.toml", "--scheduler", ""],
    ["analyse", ""],
])
def test_empty_option_values_are_refused(tmp_path, args):
    cfg = write(tmp_path / "c.toml", TINY)
    proc = run([cfg if a == "CFG" else a for a in args], cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "empty" in one_line(proc)
    assert sorted(os.listdir(tmp_path)) == ["c.toml"]  # nothing written anywhere


def test_python_refuses_empty_out_and_bad_thread_counts(tmp_path):
    import grainlab
    cfg = write(tmp_path / "c.toml", TINY)
    for kwargs in ({"out": ""}, {"threads": 0}, {"threads": -2}, {"threads": 2000}, {"threads": 1.5},
                   {"threads": True}):
        with pytest.raises(grainlab.ConfigError) as e:
            grainlab.run(cfg, **{"out": str(tmp_path / "o"), **kwargs})
        key = "out" if "out" in kwargs else "threads"
        assert key in str(e.value)
    with pytest.raises(grainlab.ConfigError):
        grainlab.sweep(cfg, {"contact.beta": [0, 1]}, out="")
    with pytest.raises(grainlab.ConfigError):
        grainlab.Simulation(cfg, threads=0)
    assert sorted(os.listdir(tmp_path)) == ["c.toml"]


# --- the Python module: one Simulation, several threads; fork after OpenMP -------------------------

def test_two_python_threads_stepping_one_simulation_is_refused_not_a_crash(tmp_path):
    import grainlab
    sim = grainlab.Simulation(write(tmp_path / "c.toml", TINY), threads=1)
    start = sim.step_count
    errors, done = [], []

    def worker():
        try:
            sim.step(20000)
            done.append(1)
        except RuntimeError as e:
            errors.append(str(e))

    threads = [threading.Thread(target=worker) for _ in range(4)]
    for t in threads:
        t.start()
    # While one thread steps, the others (and this one) are refused with a clear error.
    seen_busy = False
    for _ in range(2000):
        try:
            sim.positions
        except RuntimeError as e:
            assert "another thread" in str(e)
            seen_busy = True
            break
    for t in threads:
        t.join()
    assert all("another thread" in e for e in errors)
    assert len(done) + len(errors) == 4 and done
    # Every step that was not refused ran, none was lost.
    assert sim.step_count == start + 20000 * len(done)
    assert seen_busy or errors
    sim.step(10)  # idle again: usable


def _step_in_child(cfg, queue):
    import warnings
    import grainlab
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sim = grainlab.Simulation(cfg, threads=2)
        sim.step(200)
    queue.put((sim.step_count, [str(w.message) for w in caught]))


def test_fork_after_openmp_threads_works_on_one_thread_with_a_warning(tmp_path):
    import grainlab
    cfg = write(tmp_path / "c.toml", TINY)
    parent = grainlab.Simulation(cfg, threads=2)
    parent.step(200)  # OpenMP teams of two threads now exist in this process
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    child = ctx.Process(target=_step_in_child, args=(cfg, queue))
    child.start()
    child.join(120)
    if child.is_alive():
        child.kill()
        pytest.fail("a child forked after OpenMP threads deadlocked on its first step")
    assert child.exitcode == 0
    steps, warnings = queue.get(timeout=10)
    assert steps > 200
    assert any("forked" in w and "spawn" in w for w in warnings), warnings


# --- results folders ------------------------------------------------------------------------------

def test_two_runs_into_one_new_folder_at_once(tmp_path):
    cfg = write(tmp_path / "c.toml", LONGER)
    out = tmp_path / "out"
    procs = [subprocess.Popen([GRAINLAB, "run", cfg, "--out", str(out), "--quiet", "--set", f"sample.seed={s}"],
                              stderr=subprocess.PIPE, text=True) for s in (1, 2)]
    codes = []
    for p in procs:
        _, e = p.communicate(timeout=300)
        codes.append((p.returncode, e))
    assert sorted(c for c, _ in codes) == [0, 2], codes
    refused = next(e for c, e in codes if c == 2)
    assert "another grainlab run" in refused and str(out) in refused
    # The folder is one run's: its config, packing and summary agree.
    summary = json.loads((out / "summary.json").read_text())
    assert (out / "config.resolved.toml").read_text().startswith(f"# grainlab run {summary['run_id']}")
    seed = int(next(l for l in (out / "config.resolved.toml").read_text().splitlines()
                    if l.strip().startswith("seed")).split("=")[1])
    assert f"seed {seed}" in (out / "packing.txt").read_text().splitlines()[1] or \
        f"seed {seed}" in (out / "packing.txt").read_text()


def test_rerun_keeps_files_a_user_added(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    out = tmp_path / "out"
    assert run(["run", cfg, "--out", str(out), "--quiet"]).returncode == 0
    (out / "notes.txt").write_text("my notes\n")
    (out / "mine").mkdir()
    (out / "mine" / "a.csv").write_text("1,2\n")
    proc = run(["run", cfg, "--out", str(out), "--quiet", "--set", "sample.seed=4"])
    assert proc.returncode == 0, proc.stderr
    assert (out / "notes.txt").read_text() == "my notes\n"
    assert (out / "mine" / "a.csv").read_text() == "1,2\n"
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"
    assert "notes.txt" not in (out / ".grainlab-manifest").read_text().split()
    # and again: the kept files are still the user's
    assert run(["run", cfg, "--out", str(out), "--quiet"]).returncode == 0
    assert (out / "notes.txt").read_text() == "my notes\n"


def test_completed_is_written_only_after_the_plots(tmp_path):
    """Polls the folder while the run plots: whenever summary.json says completed, the plots and
    the manifest are already there."""
    cfg = write(tmp_path / "c.toml", TINY.replace("plots = false", "plots = true"))
    out = tmp_path / "out"
    proc = subprocess.Popen([GRAINLAB, "run", cfg, "--out", str(out), "--quiet"])
    seen = set()
    while proc.poll() is None:
        try:
            status = json.loads((out / "summary.json").read_text())["status"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.005)
            continue
        seen.add(status)
        if status == "completed":
            assert (out / "plots" / "overview.png").exists()
            assert (out / ".grainlab-manifest").exists()
        time.sleep(0.005)
    assert proc.returncode == 0
    assert "finishing" in seen  # the poll saw the run between its curves and its plots


def test_resume_finishes_a_run_killed_while_plotting(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY.replace("plots = false", "plots = true"))
    out = tmp_path / "out"
    assert run(["run", cfg, "--out", str(out), "--quiet"]).returncode == 0
    # The state a kill during plotting leaves: curves and summary written, plots and manifest not.
    summary = json.loads((out / "summary.json").read_text())
    summary["status"] = "finishing"
    (out / "summary.json").write_text(json.dumps(summary))
    shutil.rmtree(out / "plots")
    (out / ".grainlab-manifest").unlink()
    proc = run(["resume", str(out)])
    assert proc.returncode == 0, proc.stderr
    assert "run completed" in proc.stdout
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"
    assert (out / "plots" / "overview.png").exists() and (out / ".grainlab-manifest").exists()
    assert "already completed" in run(["resume", str(out)]).stdout


def test_checkpoint_copied_from_another_runs_folder_is_refused(tmp_path):
    cfg = write(tmp_path / "c.toml", LONGER)
    a, b = tmp_path / "a", tmp_path / "b"
    killed_during_shear(cfg, a)
    killed_during_shear(cfg, b)
    # Same config (same hash), another run: b's config and checkpoint copied into a.
    shutil.copy(b / "checkpoint" / "state.bin", a / "checkpoint" / "state.bin")
    proc = run(["resume", str(a), "--quiet"])
    assert proc.returncode == 2
    assert "another run" in one_line(proc) or "belongs to run" in one_line(proc)
    shutil.copy(b / "config.resolved.toml", a / "config.resolved.toml")
    # The run ids now agree, but a's packing.txt is not the one b's run saved: refused as long as
    # the packings differ (here they are the same sample, so edit a's packing).
    text = (a / "packing.txt").read_text().splitlines(keepends=True)
    (a / "packing.txt").write_text("".join(text[:-1]) + text[-1].replace("e", "E", 1))
    proc = run(["resume", str(a), "--quiet"])
    assert proc.returncode == 2 and "packing.txt" in one_line(proc), proc.stderr
    # b itself resumes.
    assert run(["resume", str(b), "--quiet"]).returncode == 0


def test_moved_results_folder_resumes_without_its_input_files(tmp_path):
    """resume never reads the files a config names (the state is in the checkpoint): a results
    folder moved away from its grading list (or with the list deleted) still resumes."""
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    (inputs / "grains.csv").write_text("".join(f"{0.004 + 0.002 * (i % 5) / 4:.6f}\n" for i in range(100)))
    cfg = write(inputs / "c.toml", LONGER.replace(
        'grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }',
        'grading = { type = "list", file = "grains.csv" }'))
    folder = tmp_path / "run"
    killed_during_shear(cfg, folder)
    moved = tmp_path / "elsewhere" / "run"
    moved.parent.mkdir()
    shutil.move(str(folder), str(moved))
    shutil.rmtree(inputs)
    proc = run(["resume", str(moved), "--quiet"])
    assert proc.returncode == 0, proc.stderr
    assert json.loads((moved / "summary.json").read_text())["status"] == "completed"
