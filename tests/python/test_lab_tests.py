"""The laboratory tests on the boundary-control seam (issue 24): undrained (constant-volume)
triaxial on both boundaries, the oedometer and cyclic triaxial, end to end through the CLI on small
soft samples. What each test's columns and summary say is recomputed here from its time series;
resume after a kill is bit-identical; every new key's bad value exits 2 naming key, value and what
is allowed. (Against analytic numbers: tests/unit/test_boundary_control.cpp, the FCC lattice.)"""
import csv
import json
import math
import os
import subprocess
import tomllib

import numpy as np
import pytest

from conftest import GRAINLAB, kill_after_second_checkpoint

DATA = os.path.join(os.path.dirname(__file__), "..", "data")
CONFIG = os.path.join(DATA, "small-triaxial.toml")
# Soft grains (Ec = 3e8 Pa): strains of the reversing tests are ~1e-2 instead of ~1e-4, and the
# time step is larger, so each run takes seconds.
SOFT = ["sample.n_particles=150", "contact.young=3e8", "output.plots=false", "output.vtk_every_strain=0"]


def sets(*extra):
    return [a for s in SOFT + list(extra) for a in ("--set", s)]


def run(out, *extra, threads=1):
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(out), "--quiet", "--threads", str(threads),
                           *sets(*extra)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return read(out)


def read(out):
    with open(out / "timeseries.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    cols = {k: np.array([float(r[k]) if r[k] != "" else math.nan for r in rows]) for k in rows[0]}
    return cols, json.loads((out / "summary.json").read_text())


@pytest.mark.parametrize("boundary,allowed", [("walls", 1e-5), ("periodic", 1e-6)])
def test_undrained_triaxial_holds_the_volume_and_reports_u(tmp_path, boundary, allowed):
    c, s = run(tmp_path / "cu", 'test.drainage="undrained"', f'test.boundary="{boundary}"',
               "test.final_axial_strain=0.02", "sample.e0_tolerance=1.0")
    assert s["drainage"] == "undrained" and s["status"] == "completed"
    p0 = s["confining_pressure"]
    # u is the change of lateral total stress the constant volume needs: p0 - (sigma2 + sigma3)/2.
    assert np.allclose(c["u"], p0 - 0.5 * (c["sigma2"] + c["sigma3"]), rtol=0, atol=1e-7 * p0)
    assert np.abs(c["eps_v"]).max() < allowed and s["volume_drift_max"] < allowed
    assert s["u_max"] == pytest.approx(c["u"].max()) and s["p_min"] == pytest.approx(c["p"].min())
    # The axial strain was imposed while the lateral axes took it up: eps2 = eps3 < 0, sum ~ 0.
    assert c["eps1"][-1] == pytest.approx(0.02, abs=1e-3)
    assert c["eps2"][-1] < 0 and c["eps3"][-1] < 0
    assert isinstance(s["liquefied"], bool)


ATMOSPHERIC, VAPOUR = 101325.0, 2339.0  # Pa: the numbers docs/laboratory.md states for cavitation


def test_cavitation_caps_the_suction_and_drains_the_sample(tmp_path):
    """A dense sample sheared undrained dilates, and u falls far below -p0 (the ideal constraint:
    water that takes any tension). With test.back_pressure = 0 the water cavitates at
    u_cav = -(0 + 101.325 - 2.339) kPa: u then stays there, the lateral effective stress is held
    at p0 - u_cav and the volume grows; before it, the volume held."""
    common = ['test.drainage="undrained"', 'test.boundary="periodic"', "test.final_axial_strain=0.04",
              "sample.e0_tolerance=1.0", "test.probe_strain=0"]
    ideal, si = run(tmp_path / "ideal", *common)
    u_cav = -(0.0 + ATMOSPHERIC - VAPOUR)
    # Without the limit the same sample's suction goes beyond u_cav (else this test could not fail).
    assert si["u_min"] < 1.5 * u_cav and si["cavitated"] is None and si["cavitation_pressure"] is None
    c, s = run(tmp_path / "cav", *common, "test.back_pressure=0")
    p0 = s["confining_pressure"]
    assert s["cavitation_pressure"] == u_cav
    assert s["cavitated"] is True and s["cavitations"] >= 1
    e_cav = s["cavitation_strain"]
    assert 0.0 < e_cav < 0.04
    # The ideal run passes u_cav at the same strain (identical until then).
    k = np.argmax(ideal["u"] <= u_cav)
    assert ideal["eps1"][k] == pytest.approx(e_cav, abs=2e-3)
    before, after = c["eps1"] < e_cav, c["eps1"] > e_cav + 0.005
    assert before.sum() > 3 and after.sum() > 3
    assert np.abs(c["eps_v"][before]).max() <= 1e-6 and s["volume_drift_max"] <= 1e-6
    assert (c["u"][before] > u_cav).all()
    # Cavitated: u = p0 - sigma3' held at u_cav to the servo's tolerance, the sample dilates
    # (eps_v < 0: compression positive) and p' stays far below the ideal run's.
    assert np.abs(c["u"][after] - u_cav).max() < 0.05 * p0
    assert c["eps_v"][-1] < -1e-3 and np.all(np.diff(c["eps_v"][after]) < 1e-6)
    assert c["p"][-1] < 0.7 * ideal["p"][-1]
    assert s["u_min"] == pytest.approx(c["u"].min())
    assert any("cavitated" in w for w in s["warnings"])


def test_cavitation_in_undrained_simple_shear_holds_sigma_zz(tmp_path):
    """Simple shear keeps the volume with H_zz fixed: cavitated, sigma_zz is held at p0 - u_cav."""
    c, s = run(tmp_path / "ss", 'test.type="simple-shear"', 'test.boundary="periodic"', 'test.drainage="undrained"',
               "test.back_pressure=0", "test.final_shear_strain=0.12", "sample.e0_tolerance=1.0", "test.probe_strain=0")
    u_cav, p0 = -(ATMOSPHERIC - VAPOUR), s["confining_pressure"]
    assert s["cavitated"] is True and s["volume_drift_max"] <= 1e-6
    after = c["gamma"] > c["gamma"][0] + s["cavitation_strain"] + 0.005
    assert after.sum() > 3
    assert np.abs(c["sigma1"][after] - (p0 - u_cav)).max() < 0.05 * p0
    assert np.allclose(c["u"], p0 - c["sigma1"], rtol=0, atol=1e-7 * p0)
    assert c["eps_v"][-1] < -1e-3


def test_cavities_close_when_cyclic_shear_brings_the_sample_back_to_its_volume(tmp_path):
    """Undrained cyclic simple shear of a dense sample: on each loading u falls to u_cav and the
    water cavitates (drained at sigma_zz = p0 - u_cav, the sample dilates); on unloading the sample
    contracts back to its initial volume, the cavities close, and u rises again. The sample can
    never be denser than at the start while cavitated: a vapour cavity cannot carry compression
    (before the fix the water re-cavitated on the step after each closing, at the servo's u_cav,
    and the sample compacted by 1e-3 at u = u_cav)."""
    c, s = run(tmp_path / "cyc", 'test.type="cyclic-simple-shear"', 'test.boundary="periodic"',
               'test.drainage="undrained"', "test.back_pressure=0", "test.shear_strain_amplitudes=[0.01]",
               "test.cycles_per_amplitude=2", "sample.e0_tolerance=1.0", "test.probe_strain=0")
    u_cav, p0 = -(ATMOSPHERIC - VAPOUR), s["confining_pressure"]
    margin = 5e-3 * (p0 - u_cav)  # kCavityMargin (docs/laboratory.md, Cavitation)
    assert s["status"] == "completed" and s["cavitated"] is True
    # Cavitated on every loading of the cycle (quarter, +, -, ...): several, not one.
    assert s["cavitations"] >= 3
    at_cav = np.abs(c["u"] - u_cav) < 0.002 * p0
    assert at_cav.sum() > 5
    # While cavitated the volume only grew: eps_v (compression positive) <= the constraint's drift.
    assert c["eps_v"][at_cav].max() <= 1e-6
    # Closed again: after the first cavitation u rises well above u_cav at constant volume.
    first = np.argmax(at_cav)
    closed = (c["u"] > u_cav + 0.1 * p0) & (np.arange(len(c["u"])) > first)
    assert closed.sum() > 5
    assert np.abs(c["eps_v"][closed]).max() <= 1e-6 and s["volume_drift_max"] <= 1e-6
    # Never below u_cav by more than the re-cavitation margin.
    assert c["u"].min() >= u_cav - margin


def local_rates(c, ramp_steps):
    """(dε1/dt between consecutive records, mean p of the interval) after the loading ramp."""
    t, e1, p, step = c["time"], c["eps1"], c["p"], c["step"]
    keep = step[:-1] - step[0] > ramp_steps
    return (np.diff(e1) / np.diff(t))[keep], p[1:][keep]


@pytest.mark.parametrize("follows", [False, True])
def test_rate_follows_pressure_holds_the_inertial_number_as_p_falls(tmp_path, follows):
    """A loose sample sheared undrained loses p' (u rises): with test.rate_follows_pressure the
    platens' strain rate between records is the rate at p0 times sqrt(p'/(1.1 p0)) (clamped to
    [0.02, 1]), recomputed here from the time series, so I stays under its p0 value; without the key
    the rate stays the one at p0 and I exceeds 1e-3. The same check on the run without the key fails
    (the first parameter): the rate law is what the records show, not what the summary says."""
    proc = subprocess.run([GRAINLAB, "run", "preset:csl-loose", "--out", str(tmp_path / "r"), "--quiet", "--threads", "1",
                           "--set", "sample.n_particles=300", "--set", "test.final_axial_strain=0.03",
                           "--set", "test.probe_strain=0", "--set", 'test.drainage="undrained"',
                           "--set", f"test.rate_follows_pressure={'true' if follows else 'false'}",
                           "--set", "output.plots=false", "--set", "output.vtk_every_strain=0"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    c, s = read(tmp_path / "r")
    p0, rate = s["confining_pressure"], s["strain_rate"]
    assert c["p"].min() < 0.5 * p0  # the loose sample contracts: p' falls well below p0
    # The loading ramp: 40 servo integral times (docs/laboratory.md §2).
    with open(tmp_path / "r" / "config.resolved.toml", "rb") as f:
        ramp_steps = 40 * tomllib.load(f)["solver"]["servo_integral_steps"]
    r, p = local_rates(c, ramp_steps)
    expected = rate * np.clip(np.sqrt(p / (1.1 * p0)), 0.02, 1.0)
    slowed = p < 0.8 * p0
    assert slowed.sum() >= 5
    matches = np.abs(r[slowed] / expected[slowed] - 1) < 0.1
    if follows:
        assert matches.mean() > 0.9, (r[slowed] / expected[slowed])
        assert s["rate_factor_min"] == pytest.approx(np.sqrt(c["p"].min() / (1.1 * p0)), rel=0.15)
        assert s["inertial_number_max"] <= 1e-3 and s["quasi_static"] is True
        # The records' I is the one of the slowed rate: I = rate factor d50 sqrt(rho/p).
        assert c["inertial_number"].max() <= 1e-3
    else:
        assert matches.mean() < 0.5
        assert np.allclose(r, rate, rtol=0.02)
        assert "rate_factor_min" not in s and s["inertial_number_max"] > 1e-3


def test_oedometer_keeps_lateral_strain_zero_and_reports_k0(tmp_path):
    c, s = run(tmp_path / "oed", 'test.type="oedometer"', "test.max_axial_stress=800e3", "test.unload_axial_stress=200e3",
               "sample.e0_tolerance=1.0")
    assert np.all(c["eps2"] == 0) and np.all(c["eps3"] == 0)
    d = c["load_direction"]
    assert d[0] == 1 and d[-1] == -1 and np.count_nonzero(np.diff(d)) == 1  # one reversal
    assert c["sigma1"].max() >= 0.95 * 800e3 and c["sigma1"][-1] <= 1.1 * 200e3
    # K0 recomputed by its definition: sigma_h/sigma_v over the loading records at or above
    # sqrt(p0 sigma_v,max); Cc the least-squares slope of e on log10 sigma_v there.
    p0, smax = s["confining_pressure"], c["sigma1"].max()
    load = (d > 0) & (c["sigma1"] >= math.sqrt(p0 * smax))
    k = 0.5 * (c["sigma2"] + c["sigma3"]) / c["sigma1"]
    assert s["K0"] == pytest.approx(k[load].mean(), rel=1e-6)
    assert s["Cc"] == pytest.approx(-np.polyfit(np.log10(c["sigma1"][load]), c["e"][load], 1)[0], rel=1e-4)
    assert 0.2 < s["K0"] < 1.0 and s["Cc"] > 0 and s["Cs"] is not None
    assert s["K0_unloading"] > s["K0"]  # unloading leaves a locked-in lateral stress
    assert "phi_peak_deg" not in s and "cs_q_over_p" not in s


@pytest.mark.parametrize("drainage", ["drained", "undrained"])
def test_cyclic_triaxial_cycles_between_the_amplitudes(tmp_path, drainage):
    c, s = run(tmp_path / "cyc", 'test.type="cyclic-triaxial"', f'test.drainage="{drainage}"', "test.csr=0.15",
               "test.n_cycles=2", "sample.e0_tolerance=1.0")
    qcyc = 2 * 0.15 * s["confining_pressure"]
    assert s["cycles"] == 2.0 and c["cycle"][-1] == 2.0
    # The reversal records (where `cycle` steps by a half) are at the amplitude, and q never leaves
    # it by more than a step's worth.
    steps = np.flatnonzero(np.diff(c["cycle"]) != 0) + 1
    assert len(steps) == 4  # two reversals per cycle; the fourth ends the test
    assert np.all(np.abs(c["q"][steps]) >= 0.9 * qcyc)
    assert c["q"].max() < 1.2 * qcyc and c["q"].min() > -1.2 * qcyc
    assert s["n_cycles_to_liquefaction"] is None
    if drainage == "undrained":
        assert s["ru_max"] > 0 and s["volume_drift_max"] < 1e-5
        assert np.allclose(c["u"], s["confining_pressure"] - 0.5 * (c["sigma2"] + c["sigma3"]), atol=1e-2)
    else:
        assert s["ru_max"] is None and "u" not in c


VOLATILE = {"wall_seconds", "particle_steps_per_s", "threads_used", "run_id"}


@pytest.mark.parametrize("test", [
    ['test.type="oedometer"', "test.max_axial_stress=800e3", "test.unload_axial_stress=200e3"],
    ['test.type="cyclic-triaxial"', 'test.drainage="undrained"', "test.csr=0.15", "test.n_cycles=2"],
    ['test.drainage="undrained"', "test.final_axial_strain=0.02"],
    ['test.drainage="undrained"', "test.final_axial_strain=0.02", "test.back_pressure=0", 'test.boundary="periodic"'],
])
def test_kill_and_resume_is_bit_identical(tmp_path, test):
    extra = test + ["sample.e0_tolerance=1.0", "output.checkpoint_every=1e-4"]
    whole = tmp_path / "whole"
    a = run(whole, *extra)
    cut = tmp_path / "cut"
    proc = subprocess.Popen([GRAINLAB, "run", CONFIG, "--out", str(cut), "--quiet", "--threads", "1", *sets(*extra)])
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=300)
    assert not (cut / "timeseries.csv").exists()
    resumed = subprocess.run([GRAINLAB, "resume", str(cut), "--quiet"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert (whole / "timeseries.csv").read_text() == (cut / "timeseries.csv").read_text()
    sa = {k: v for k, v in a[1].items() if k not in VOLATILE}
    sb = {k: v for k, v in json.loads((cut / "summary.json").read_text()).items() if k not in VOLATILE}
    assert sa == sb


@pytest.mark.parametrize("extra,key,words", [
    (['test.drainage="partial"'], "test.drainage", ['"drained", "undrained"']),
    (['test.type="oedometer"', "test.max_axial_stress=50e3"], "test.max_axial_stress", ["above test.confining_pressure"]),
    (['test.type="oedometer"', "test.unload_axial_stress=2e6"], "test.unload_axial_stress", ["below test.max_axial_stress"]),
    (['test.type="cyclic-triaxial"', "test.csr=0"], "test.csr", ["(0, 2]"]),
    (['test.type="cyclic-triaxial"', "test.n_cycles=0"], "test.n_cycles", ["1"]),
    (['test.type="cyclic-triaxial"', "test.ru_limit=1.5"], "test.ru_limit", ["(0, 1]"]),
    (['test.type="cyclic-triaxial"', "test.liquefaction_da_strain=0.9"], "test.liquefaction_da_strain", ["(0, 0.5]"]),
    (['test.type="stress-path"'], "test.path", ['needs its table']),
    (['test.rate_follows_pressure="yes"'], "test.rate_follows_pressure", ["true", "false"]),
    (['test.drainage="undrained"', "test.back_pressure=-1"], "test.back_pressure", ["[0, 1e9]", "cavitates"]),
    (['test.drainage="undrained"', 'test.back_pressure="high"'], "test.back_pressure", ["number"]),
])
def test_bad_input_of_the_new_tests_is_refused(tmp_path, extra, key, words):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets(*extra)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and key in line, line
    for w in words:
        assert w in line, f"{w!r} not in {line}"


@pytest.mark.parametrize("extra,key", [
    (['test.type="oedometer"', 'test.drainage="undrained"'], "test.drainage"),
    (["test.csr=0.2"], "test.csr"),
    (['test.type="cyclic-triaxial"', "test.max_axial_stress=2e6"], "test.max_axial_stress"),
    (['test.type="isotropic"', "test.rate_follows_pressure=true"], "test.rate_follows_pressure"),
])
def test_keys_of_another_test_warn(extra, key):
    """As for the other tests' keys (a config reused with --set test.type=...): ignored, with a
    warning naming the key and the test type."""
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets(*extra)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert f"warning: {key} = " in proc.stderr and "is ignored" in proc.stderr and "test.type" in proc.stderr


def test_back_pressure_of_a_drained_test_warns():
    """test.back_pressure only means something when the volume is held: a drained test ignores it,
    with a warning naming test.drainage."""
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets("test.back_pressure=300e3")], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "warning: test.back_pressure = " in proc.stderr and "test.drainage" in proc.stderr
