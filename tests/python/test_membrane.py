"""test.boundary = "membrane" end to end: a drained and an undrained triaxial test of a cylinder in
a flexible membrane, a kill and resume, and the inputs a membrane refuses (exit 2 naming the key)."""
import csv
import json
import subprocess

import pytest

from conftest import GRAINLAB, kill_after_second_checkpoint

# 1200 spheres of 4-6 mm: a cylinder about 8.3 d50 across (the smallest preflight allows is 8).
CONFIG = """\
[sample]
n_particles = 1200
grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }
e0 = 0.62
seed = 4
prep_friction_deg = 0.0

[contact]
young = 3.0e9
friction_deg = 30.0

[test]
type = "triaxial"
boundary = "membrane"
confining_pressure = 100.0e3
axial_strain_rate = 2.0
final_axial_strain = 0.02

[solver]
threads = 1

[output]
record_every_strain = 0.002
vtk_every_strain = 0.01
checkpoint_every = 0.004
band_strain_window = 0.005
plots = false
"""


def write(tmp_path, text, name="membrane.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def rows(out):
    with open(out / "timeseries.csv") as f:
        return [{k: float(v) if v not in ("", "null") else None for k, v in r.items()} for r in csv.DictReader(f)]


@pytest.fixture(scope="module")
def drained(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("membrane")
    out = tmp / "out"
    proc = subprocess.run([GRAINLAB, "run", write(tmp, CONFIG), "--out", str(out), "--quiet"], capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return out


def test_drained_membrane_triaxial_holds_the_cell_pressure(drained):
    summary = json.loads((drained / "summary.json").read_text())
    assert summary["status"] == "completed"
    m = summary["membrane"]
    assert m["bins_around"] >= 8 and m["bins_along"] >= 4
    assert 0.9 < m["end_filled_bins_fraction"] <= 1.0
    # The radial stress is the cell pressure plus the sleeve's hoop term, which is small here.
    assert m["end_radial_stress"] == pytest.approx(m["end_cell_pressure"] + m["end_membrane_correction"], rel=1e-9)
    assert 0.0 <= m["end_membrane_correction"] < 0.02 * 100e3
    r = rows(drained)
    e0 = r[0]["e"]
    for row in r:
        # sigma2 = sigma3: one lateral stress; it is the cell pressure (plus the hoop term).
        assert row["sigma2"] == row["sigma3"]
        assert row["sigma3"] == pytest.approx(100e3, rel=0.02)
        # The void ratio and the volumetric strain come from the same enclosed volume.
        assert row["e"] == pytest.approx((1 + e0) * (1 - row["eps_v"]) - 1, abs=1e-9)
    assert max(row["q"] for row in r) > 100e3  # the sample carries a deviator
    # Lateral strains of a cylinder: the same diameter in x and y.
    assert all(row["eps2"] == row["eps3"] for row in r)
    vtk = drained / "vtk"
    assert (vtk / "membrane.pvd").exists() and list(vtk.glob("membrane_*.vtu"))
    assert b"membrane_force" in sorted(vtk.glob("particles_*.vtu"))[-1].read_bytes()


def test_undrained_membrane_keeps_the_volume(tmp_path):
    cfg = CONFIG.replace('boundary = "membrane"', 'boundary = "membrane"\ndrainage = "undrained"')
    cfg = cfg.replace("final_axial_strain = 0.02", "final_axial_strain = 0.01")
    out = tmp_path / "out"
    proc = subprocess.run([GRAINLAB, "run", write(tmp_path, cfg), "--out", str(out), "--quiet"], capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    r = rows(out)
    # The membrane's pressure is servoed to the volume: it stays within 0.1 % of the start.
    assert max(abs(row["eps_v"]) for row in r) < 1e-3
    # A dense sample sheared undrained wants to dilate: the lateral stress rises (negative excess
    # pore pressure), where a drained test holds it at p.
    assert r[-1]["sigma3"] > 100e3


def test_membrane_kill_and_resume_is_bit_identical(tmp_path):
    config = write(tmp_path, CONFIG.replace("final_axial_strain = 0.02", "final_axial_strain = 0.012"))
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    assert subprocess.run([GRAINLAB, "run", config, "--out", str(whole), "--quiet"], timeout=900).returncode == 0
    proc = subprocess.Popen([GRAINLAB, "run", config, "--out", str(cut), "--quiet"])
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=600)
    assert not (cut / "summary.json").exists()
    assert subprocess.run([GRAINLAB, "resume", str(cut), "--quiet"], timeout=900).returncode == 0
    assert (whole / "timeseries.csv").read_text() == (cut / "timeseries.csv").read_text()
    volatile = {"wall_seconds", "particle_steps_per_s", "threads_used", "run_id"}
    a, b = (json.loads((d / "summary.json").read_text()) for d in (whole, cut))
    assert {k: v for k, v in a.items() if k not in volatile} == {k: v for k, v in b.items() if k not in volatile}


BAD = [
    # (overrides, key named, value named)
    (["test.membrane_thickness=0"], "test.membrane_thickness", "0"),
    (["test.membrane_young=-1"], "test.membrane_young", "-1"),
    (["test.aspect_ratio=10"], "test.aspect_ratio", "10"),
    (["test.membrane_bin_d50=0.1"], "test.membrane_bin_d50", "0.1"),
    (['test.type="true-triaxial"'], "test.type", "true-triaxial"),
    (['test.type="oedometer"'], "test.type", "oedometer"),
    (['test.type="simple-shear"'], "test.type", "simple-shear"),
    (['sample.method="lattice"'], "sample.method", "lattice"),
    (['sample.shape={ type = "ellipsoid", elongation = 0.8 }'], "sample.shape.type", "ellipsoid"),
    (["sample.gravity=[0.0, 0.0, -9.81]"], "sample.gravity", "-9.81"),
    (["contact.friction_deg=0"], "contact.friction_deg", "0"),
    (['test.boundary="walls"', "test.aspect_ratio=2"], "test.aspect_ratio", "membrane"),
]


@pytest.mark.parametrize("overrides,key,value", BAD)
def test_bad_membrane_input_exit_2_names_key_and_value(tmp_path, overrides, key, value):
    args = [GRAINLAB, "check", write(tmp_path, CONFIG)]
    for o in overrides:
        args += ["--set", o]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    line = proc.stderr.strip().splitlines()[-1]
    assert key in line and value in line, line


def test_a_membrane_around_a_periodic_packing_is_refused(tmp_path):
    # A packing file holds a box or a cell, never a membrane sample.
    packing = tmp_path / "cell.txt"
    packing.write_text("# grainlab packing\n")
    proc = subprocess.run([GRAINLAB, "check", write(tmp_path, CONFIG), "--set", f'sample.packing="{packing}"'],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "sample.packing" in proc.stderr and "membrane" in proc.stderr


def test_a_membrane_sample_too_small_for_a_band_is_refused(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.run([GRAINLAB, "run", write(tmp_path, CONFIG), "--set", "sample.n_particles=200", "--out", str(out),
                           "--quiet"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "sample.n_particles = 200" in proc.stderr and "d50" in proc.stderr and "band" in proc.stderr
    assert not (out / "timeseries.csv").exists()
