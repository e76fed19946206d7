"""The Python module (docs/python.md): configs with the CLI's errors, in-process runs bit-identical
to the CLI's, Ctrl-C and progress, numpy views without copies, boundary control checked against hand
computations, the contact copy against the engine's own measurements, the examples, installation
and runs on a Dask cluster."""
import _thread
import gc
import json
import os
import re
import subprocess
import sys
import threading
import tomllib

import numpy as np
import pytest

from conftest import GRAINLAB

BUILD = os.path.dirname(os.path.abspath(GRAINLAB))
PYTHON_DIR = os.path.join(BUILD, "python")
sys.path.insert(0, PYTHON_DIR)
if not os.path.isdir(os.path.join(PYTHON_DIR, "grainlab")):
    pytest.skip(f"the Python module is not built in {PYTHON_DIR} (GRAINLAB_PYTHON_MODULE=OFF)", allow_module_level=True)
# Built but not importable (e.g. an unresolved symbol) is a failure, never a skip.
import grainlab  # noqa: E402
EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python")
# A small whole triaxial test (~1-2 s on one thread).
SMALL = {"sample.n_particles": 120, "test.final_axial_strain": 0.005, "output.plots": False}
SMALL_SETS = [a for k, v in SMALL.items() for a in ("--set", f"{k}={json.dumps(v)}")]
VOLATILE = {"wall_seconds", "particle_steps_per_s", "threads_used", "run_id"}


def cli(*args):
    return subprocess.run([GRAINLAB, *args], capture_output=True, text=True, timeout=300)


# ---------------------------------------------------------------------------------------------
# Configs

@pytest.mark.parametrize("source,sets", [
    ("preset:quick-triaxial", ["contact.beta=-1"]),
    ("preset:quick-triaxial", ["contact.betta=0.1"]),
    ("preset:quick-triaxial", ["sample.method=\"sideways\""]),
    ("preset:no-such-preset", []),
    ("/nonexistent/config.toml", []),
])
def test_config_errors_are_the_cli_line(source, sets):
    proc = cli("check", source, *[a for s in sets for a in ("--set", s)])
    assert proc.returncode == 2
    line = proc.stderr.strip()
    assert line.startswith("grainlab: ") and "\n" not in line
    with pytest.raises(grainlab.ConfigError) as info:
        grainlab.load_config(source, set=sets)
    assert isinstance(info.value, ValueError)
    assert "grainlab: " + str(info.value) == line


def test_preset_name_dict_and_set_resolve_as_the_cli():
    sets = {"sample.method": "growth", "output.plots": False, "contact.beta": 0, "solver.dt_factor": 0.4}
    proc = cli("check", "preset:quick-triaxial", "--set", "sample.method=growth", "--set", "output.plots=false",
               "--set", "contact.beta=0", "--set", "solver.dt_factor=0.4")
    assert proc.returncode == 0, proc.stderr
    by_name = grainlab.load_config("quick-triaxial", set=sets)
    assert by_name.source == "preset:quick-triaxial"
    assert by_name.resolved_toml() == proc.stdout
    # The same config given as a nested dict (the preset's own table) resolves to the same values.
    as_dict = tomllib.loads(grainlab.load_config("preset:quick-triaxial").toml())
    assert grainlab.load_config(as_dict, set=sets).resolved_toml() == proc.stdout
    # A dict is validated like a file: a wrong type names the key and the value.
    with pytest.raises(grainlab.ConfigError, match=r"sample\.n_particles = 'x'"):
        grainlab.load_config({**as_dict, "sample": {**as_dict["sample"], "n_particles": "x"}})
    with pytest.raises(grainlab.ConfigError, match=r"contact\.beta = .*allowed: bool, int, float, str, list, dict"):
        grainlab.load_config({"contact": {"beta": object()}})


# ---------------------------------------------------------------------------------------------
# Runs

def without(summary, keys):
    return {k: v for k, v in summary.items() if k not in keys}


def test_run_equals_the_cli_bit_for_bit(tmp_path):
    proc = cli("run", "preset:quick-triaxial", *SMALL_SETS, "--threads", "1", "--quiet", "--out", str(tmp_path / "cli"))
    assert proc.returncode == 0, proc.stderr
    calls = []
    result = grainlab.run("quick-triaxial", set=SMALL, out=tmp_path / "py", threads=1,
                          progress=lambda phase, f, steps: calls.append((phase, f, steps)))
    expected = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert result.status == "completed"
    assert without(result.summary, VOLATILE) == without(expected, VOLATILE)
    assert (tmp_path / "py" / "timeseries.csv").read_bytes() == (tmp_path / "cli" / "timeseries.csv").read_bytes()
    # The resolved configs differ only in output.dir (and the run id of their first line).
    def resolved(folder):
        lines = (folder / "config.resolved.toml").read_text().replace(str(folder), "OUT").splitlines()
        assert lines[0].startswith("# grainlab run ")
        return lines[1:]
    assert resolved(tmp_path / "py") == resolved(tmp_path / "cli")
    # The time series as numpy: integers stay integers, the values are the CSV's.
    ts = result.timeseries
    assert ts["step"].dtype == np.int64
    rows = (tmp_path / "cli" / "timeseries.csv").read_text().splitlines()
    assert len(ts) == len(rows) - 1
    last = dict(zip(rows[0].split(","), rows[-1].split(",")))
    assert ts["q"][-1] == float(last["q"]) and ts["eps1"][-1] == float(last["eps1"])
    # Progress reached Python, phase by phase, ending with the shearing at 100 %.
    assert calls and calls[-1][1] == 1.0 and any("shear" in c[0] or "triaxial" in c[0] for c in calls)
    pandas = pytest.importorskip("pandas")
    assert isinstance(result.dataframe(), pandas.DataFrame)


def test_a_failed_run_raises_and_keeps_its_summary(tmp_path):
    with pytest.raises(grainlab.SimulationError, match="run failed: .*max_steps"):
        # A rate at which the test itself fits in 100 steps (else refused up front): the preparation fails.
        grainlab.run("quick-triaxial", set={**SMALL, "solver.max_steps": 100, "test.axial_strain_rate": 300.0},
                     out=tmp_path / "f", threads=1)
    assert json.loads((tmp_path / "f" / "summary.json").read_text())["status"] == "failed"


def test_ctrl_c_stops_the_run_cleanly_and_it_resumes(tmp_path):
    out = tmp_path / "interrupted"
    sheared = threading.Event()

    def progress(phase, fraction, steps):
        # Once the shearing is under way (a checkpoint has been written), Ctrl-C from another thread.
        if fraction > 0.25 and not sheared.is_set() and (out / "checkpoint" / "state.bin").exists():
            sheared.set()
            threading.Thread(target=_thread.interrupt_main).start()

    with pytest.raises(KeyboardInterrupt):
        grainlab.run("quick-triaxial", set={**SMALL, "test.final_axial_strain": 0.02, "output.checkpoint_every": 0.002},
                     out=out, threads=1, progress=progress)
    assert sheared.is_set()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted" and "KeyboardInterrupt" in summary["error"]
    # The folder is what a killed CLI run leaves: `grainlab resume` completes it.
    proc = cli("resume", str(out), "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"


def test_an_exception_in_the_progress_callback_stops_the_run(tmp_path):
    def progress(phase, fraction, steps):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        grainlab.run("quick-triaxial", set=SMALL, out=tmp_path / "cb", threads=1, progress=progress)
    assert json.loads((tmp_path / "cb" / "summary.json").read_text())["status"] == "interrupted"


# ---------------------------------------------------------------------------------------------
# Simulation

@pytest.fixture(scope="module")
def sim():
    return grainlab.Simulation("quick-triaxial", set={"sample.n_particles": 150}, threads=1)


def test_views_are_views(sim):
    x = sim.positions
    assert x.shape == (sim.n_particles, 3) and x.dtype == np.float64
    assert np.shares_memory(x, sim.positions) and not x.flags.owndata
    before = x.copy()
    sim.step(200)
    assert not np.array_equal(x, before)           # the old view sees the step
    assert np.array_equal(x, sim.positions)
    v = sim.velocities
    saved = v[0].copy()
    v[0] = [1e-3, 0.0, 0.0]                         # writing through the view reaches the engine
    assert np.array_equal(sim.velocities[0], [1e-3, 0.0, 0.0])
    v[0] = saved
    for name in ("radii", "ids", "orientations", "semi_axes", "angular_velocities", "masses"):
        view = getattr(sim, name)
        assert not view.flags.writeable and not view.flags.owndata
        with pytest.raises(ValueError):
            view[0] = 0
    assert np.allclose(np.linalg.norm(sim.orientations, axis=1), 1.0)
    assert np.array_equal(sim.semi_axes, np.repeat(sim.radii[:, None], 3, axis=1))  # spheres
    assert np.allclose(sim.masses, 2600.0 * 4.0 / 3.0 * np.pi * sim.radii ** 3)
    assert sorted(sim.ids) == list(range(sim.n_particles))


def test_a_view_keeps_its_simulation_alive():
    x = grainlab.Simulation("quick-triaxial", set={"sample.n_particles": 60, "sample.e0_tolerance": 1.0},
                            threads=1).positions
    gc.collect()
    assert np.isfinite(x).all() and x.shape == (60, 3)


def test_strain_rate_and_stress_targets(sim):
    # Platens at an engineering rate r of the reference height: eps_z = r t exactly (hand computation).
    sim.hold_isotropic(100e3)
    sim.reset_reference()
    rate = sim.inertial_rate(1e-3)
    sim.set_strain_rate(2, rate)
    sim.set_stress(0, 150e3)
    sim.set_stress(1, 150e3)
    n = 3000
    sim.step(n)
    assert sim.strain[2] == pytest.approx(rate * n * sim.dt, rel=1e-9)
    assert sim.volumetric_strain == pytest.approx(1 - sim.volume / (sim.volume / (1 - sim.volumetric_strain)))
    # The lateral servos reach the new target (a 50 % step of sigma_x, sigma_y).
    s = sim.boundary_stress
    assert s[0] == pytest.approx(150e3, rel=0.03) and s[1] == pytest.approx(150e3, rel=0.03)
    # Wall by wall (side 0: lower, 1: upper): the x walls to 120 kPa, the y walls keep 150 kPa.
    sim.set_stress(0, 120e3, side=0)
    sim.set_stress(0, 120e3, side=1)
    sim.step(3000)
    w = sim.wall_stresses
    assert w[0] == pytest.approx(120e3, rel=0.03) and w[1] == pytest.approx(120e3, rel=0.03)
    assert w[2] == pytest.approx(150e3, rel=0.03) and w[3] == pytest.approx(150e3, rel=0.03)
    with pytest.raises(ValueError, match="axis"):
        sim.set_stress(3, 1.0)
    with pytest.raises(ValueError, match="only a periodic cell"):
        sim.set_shear_rate(1.0)
    with pytest.raises(ValueError, match="finite"):
        sim.set_strain_rate(2, float("nan"))


@pytest.mark.parametrize("preset", ["quick-triaxial", "periodic-triaxial"])
def test_constant_volume_through_the_seam(preset):
    # Undrained shearing of a dry sample from Python: the lateral axes take up the axial strain, so
    # the volume holds to rounding (walls <= 1e-5 and cell <= 1e-6 asked; both far below) while the
    # sample is strained by 0.3 %, and the lateral stresses change (u = p0 - sigma_lateral).
    sim = grainlab.Simulation(preset, set={"sample.n_particles": 200, "sample.e0_tolerance": 1.0}, threads=1)
    sim.hold_isotropic(100e3)
    sim.reset_reference()
    sim.set_constant_volume(0)
    sim.set_constant_volume(1)
    rate = sim.inertial_rate(1e-3)
    sim.set_strain_rate(2, rate)
    n = int(0.003 / (rate * sim.dt))
    sim.step(n)
    assert sim.strain[2] == pytest.approx(0.003, rel=0.01)
    assert abs(sim.volumetric_strain) < 1e-12
    assert sim.strain[0] == pytest.approx(sim.strain[1], abs=1e-9) and sim.strain[0] < -0.001
    with pytest.raises(ValueError, match="axis"):
        sim.set_constant_volume(5)


def test_periodic_cell_strain_and_simple_shear():
    sim = grainlab.Simulation("periodic-triaxial", set={"sample.n_particles": 200, "sample.prep_friction_deg": 0},
                              threads=1)
    assert sim.periodic and sim.cell.shape == (3, 3)
    sim.reset_reference()
    rate = sim.inertial_rate(1e-3)
    sim.set_strain_rate(2, rate)
    sim.step(2000)
    # dH_zz/dt = -rate H0_zz (engineering rate of the reference length), advanced by exp(L dt): eps = r t
    # up to the exponential's O(r dt) ~ 1e-7.
    assert sim.strain[2] == pytest.approx(rate * 2000 * sim.dt, rel=1e-6)
    assert sim.boundary_stress[0] == pytest.approx(sim.boundary_stress[1], rel=0.05)  # lateral servo at p
    # Simple shear L_xz = rate: H_xz grows by rate H_zz dt per step, H_zz unchanged, gamma = H_xz/H_zz
    # grows by rate t (the lateral servo's L_xx H_xz adds a little: a skewed cell after preparation).
    sim.set_strain_rate(2, 0.0)
    h0 = sim.cell
    sim.set_shear_rate(rate)
    sim.step(2000)
    h = sim.cell
    assert h[2, 2] == h0[2, 2]
    assert h[0, 2] / h[2, 2] - h0[0, 2] / h0[2, 2] == pytest.approx(rate * 2000 * sim.dt, rel=0.03)
    with pytest.raises(ValueError, match="no walls"):
        sim.set_stress(0, 1e5, side=0)


def test_contact_copy_against_the_engine(sim):
    c = sim.contacts()
    n = len(c["a"])
    assert n > 0 and all(len(v) == n for v in c.values())
    assert np.allclose(c["normal_force"] + c["tangential_force"], c["force"])
    assert np.allclose(np.einsum("ij,ij->i", c["tangential_force"], c["normal"]), 0.0, atol=1e-12)
    # Love-Weber stress from the copy (pairs: f (x) branch; walls: -f (x) arm, docs/physics.md §9) equals
    # the engine's contact stress.
    f, l, wall = c["force"], c["branch"], c["wall"]
    sigma = (np.einsum("ci,cj->ij", f[~wall], l[~wall]) - np.einsum("ci,cj->ij", f[wall], l[wall])) / sim.volume
    engine = sim.contact_stress
    assert np.allclose(sigma, engine, rtol=1e-9, atol=1e-9 * abs(engine).max()) or \
        np.allclose(sigma.T, engine, rtol=1e-9, atol=1e-9 * abs(engine).max())
    # Every wall's stress is the sum of its contacts' normal forces over its area (Newton's third law).
    lengths = sim.lengths
    for k in range(6):
        axis = k // 2
        on_wall = wall & (c["b"] == k)
        area = lengths[(axis + 1) % 3] * lengths[(axis + 2) % 3]
        assert np.abs(f[on_wall, axis]).sum() / area == pytest.approx(sim.wall_stresses[k], rel=1e-9)


def test_ctrl_c_between_steps(sim):
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    start = sim.step_count
    with pytest.raises(KeyboardInterrupt):
        sim.step(10 ** 9)
    done = sim.step_count - start
    assert 0 < done < 10 ** 9 and done % 1000 == 0  # stopped after a whole chunk
    sim.step(10)                                     # and it goes on
    assert sim.step_count == start + done + 10


# ---------------------------------------------------------------------------------------------
# Examples, installation, cluster

def run_example(name, *args, cwd):
    env = dict(os.environ, PYTHONPATH=PYTHON_DIR, OMP_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


def test_example_custom_stress_path(tmp_path):
    out = run_example("custom_stress_path.py", str(tmp_path / "path.png"), cwd=tmp_path)
    assert (tmp_path / "path.png").stat().st_size > 10000
    q_max, q_min, median = (float(v) for v in
                            re.search(r"q_max = (\S+) kPa, q_min = (\S+) kPa, .*median (\S+) %", out).groups())
    # The path it claims: compression (q > 0) reversed into extension, p held to within 2 % (median).
    assert q_max > 50 and q_min < -25 and median < 2.0


def test_example_study_loop(tmp_path):
    out = run_example("study_loop.py", str(tmp_path / "study"), cwd=tmp_path)
    assert (tmp_path / "study" / "study.png").exists()
    phi = [float(x) for x in re.findall(r"phi_peak = (\S+) deg", out)]
    # Contact moments (beta > 0) raise the peak friction angle ([W] §4.4).
    assert len(phi) == 2 and phi[1] > phi[0]


def test_example_read_results(tmp_path):
    out = run_example("read_results.py", cwd=tmp_path)
    assert "completed, 150 grains" in out and out.count("particles_") >= 2


def test_cmake_install_puts_an_importable_package_under_the_prefix(tmp_path):
    prefix = tmp_path / "prefix"
    proc = subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    site = prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "dist-packages"
    code = "import grainlab; print(grainlab.__file__); print(grainlab.executable()); print(grainlab.data_dir())"
    env = {k: v for k, v in os.environ.items() if k != "GRAINLAB_BIN"}
    proc = subprocess.run([sys.executable, "-c", code], env=dict(env, PYTHONPATH=str(site)), capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == [str(site / "grainlab" / "__init__.py"), str(prefix / "bin" / "grainlab"),
                                   str(prefix / "share" / "grainlab")]


def test_run_and_sweep_on_a_dask_client_equal_the_local_ones(tmp_path):
    distributed = pytest.importorskip("distributed")
    local = grainlab.run("quick-triaxial", set=SMALL, out=tmp_path / "local", threads=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            distributed.Client(lc) as client:
        remote = grainlab.run("quick-triaxial", set=SMALL, out=tmp_path / "remote", threads=1, client=client)
        swept = grainlab.sweep("quick-triaxial", set=SMALL, vary={"contact.beta": [0, 0.15]}, out=tmp_path / "swept",
                               threads=1, client=client)
    assert remote.status == "completed"
    assert without(remote.summary, VOLATILE) == without(local.summary, VOLATILE)
    assert set(swept.table["contact.beta"]) == {0.0, 0.15}
    case = [r for name, r in swept.cases.items() if "0.15" in name]
    assert len(case) == 1
    assert without(case[0].summary, VOLATILE | {"threads"}) == without(local.summary, VOLATILE | {"threads"})


def test_ctrl_c_during_preparation():
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        grainlab.Simulation("quick-triaxial", set={"sample.n_particles": 400}, threads=1)
    timer.join()


def test_sweep_and_run_refuse_with_the_cli_line(tmp_path):
    proc = cli("sweep", "preset:quick-triaxial", "--vary", "contact.betta=0,1", "--out", str(tmp_path / "c"))
    assert proc.returncode == 2
    with pytest.raises(grainlab.ConfigError) as info:
        grainlab.sweep("quick-triaxial", vary={"contact.betta": [0, 1]}, out=tmp_path / "p")
    assert "grainlab: " + str(info.value) == proc.stderr.strip()
    # A folder that is not grainlab's is never replaced (README "Results folder").
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(grainlab.ConfigError, match="mine"):
        grainlab.run("quick-triaxial", set=SMALL, out=tmp_path / "mine", threads=1)
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_sweep_with_seeds_gives_the_statistics_table(tmp_path):
    swept = grainlab.sweep("quick-triaxial", set=dict(SMALL, **{"sample.n_particles": 60}), seeds=2,
                           out=tmp_path / "seeds", threads=1)
    assert list(swept.table["sample.seed"]) == [1, 2]
    stats = swept.stats
    assert len(stats) == 1 and stats["seeds_completed"][0] == 2
    phi = swept.table["phi_peak_deg"]
    assert stats["phi_peak_deg_min"][0] == phi.min() and stats["phi_peak_deg_max"][0] == phi.max()
    with pytest.raises(grainlab.ConfigError, match="seeds"):
        grainlab.sweep("quick-triaxial", seeds=0, out=tmp_path / "bad")
    with pytest.raises(grainlab.ConfigError, match="vary"):
        grainlab.sweep("quick-triaxial", out=tmp_path / "bad")
