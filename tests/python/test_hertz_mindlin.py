"""contact.model = "hertz-mindlin" (issue 27 §1) end to end through the CLI: on a small soft sample
the run completes with the energy ledger closed (the stiffness-change losses booked as slip), the
rolling slots act or not as named, resume after a kill is bit-identical (the contact history holds
the last overlap; the dashpots on) and bad input exits 2 naming the key; on a simple cubic lattice
the small-strain modulus is Hertz's closed form and follows p^(1/3) (the linear law's does not
change). Two spheres against closed forms: tests/unit/test_hertz_mindlin.cpp."""
import subprocess

import numpy as np
import pytest

from conftest import GRAINLAB, kill_after_second_checkpoint
from test_lab_tests import CONFIG, VOLATILE, read

# Soft grains (G = 1.2e8 Pa, E = 2.9e8 Pa, about the soft linear samples' Ec = 3e8 Pa).
HM = ["sample.n_particles=150", 'contact.model="hertz-mindlin"', "contact.shear_modulus=1.2e8", "contact.poisson=0.2",
      "output.plots=false", "output.vtk_every_strain=0", "sample.e0_tolerance=1.0"]


def args(*extra, base=HM):
    return [a for s in list(base) + list(extra) for a in ("--set", s)]


def run(out, *extra, base=HM, check=0):
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(out), "--quiet", "--threads", "1", *args(*extra, base=base)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == check, proc.stderr
    return (read(out) if check == 0 else None), proc


def test_triaxial_completes_with_the_energy_ledger_closed(tmp_path):
    (c, s), proc = run(tmp_path / "hm", "test.final_axial_strain=0.03")
    assert s["status"] == "completed"
    # The preset's linear-law keys are ignored with a warning, not used.
    assert "contact.young" in proc.stderr and "ignored" in proc.stderr
    assert s["energy_residual_max"] is not None and s["energy_residual_max"] < 0.01
    assert np.all(c["q"][1:] > 0) and s["phi_peak_deg"] > 15
    # No rolling slot by default: no rolling dissipation.
    assert np.all(c["D_roll"] == 0)


@pytest.mark.parametrize("slot,extra", [("kozicki", []), ("rolling-linear", ["contact.rolling_friction=0.2"])])
def test_rolling_slots_act(tmp_path, slot, extra):
    (c, s), _ = run(tmp_path / slot, f'contact.rolling="{slot}"', "test.final_axial_strain=0.02", *extra)
    assert s["status"] == "completed" and c["D_roll"][-1] > 0
    assert s["energy_residual_max"] < 0.01


LATTICE = ["sample.n_particles=64", 'sample.method="lattice"', 'test.boundary="periodic"', 'test.type="isotropic"',
           'sample.grading={type="uniform", d_min=2e-3, d_max=2e-3}', "output.plots=false", "output.vtk_every_strain=0"]


def lattice_modulus(tmp_path, name, pressure, law):
    (_, s), _ = run(tmp_path / name, f"test.confining_pressure={pressure}", *law, base=LATTICE)
    assert s["nu0"] == pytest.approx(0.0, abs=0.02), s["E0_method"]
    return s["E0_MPa"] * 1e6


def test_small_strain_stiffness_of_a_lattice_follows_hertz(tmp_path):
    # A simple cubic lattice of 2 mm spheres in the periodic cell at p, probed along z: one column
    # of contacts carries F = p l^2 (l = the spacing, d to 1e-3 here), so E0 = kn / l with kn the
    # tangent stiffness at that force: Hertz's dF/dU = 3/2 (4/3 E* sqrt(R*)) U^(1/2) with
    # U = (F / (4/3 E* sqrt(R*)))^(2/3), i.e. E0 ~ p^(1/3): eight times the pressure doubles it,
    # while the linear law's E0 = kn / l does not change (tests/unit/test_moduli.cpp).
    G, nu, d = 1e9, 0.2, 2e-3
    hm = ['contact.model="hertz-mindlin"', f"contact.shear_modulus={G}", f"contact.poisson={nu}"]
    e_star = 2 * G * (1 + nu) / (2 * (1 - nu ** 2))
    hertz = 4 / 3 * e_star * np.sqrt(d / 4)
    overlap = (1e5 * d ** 2 / hertz) ** (2 / 3)
    expected = 1.5 * hertz * np.sqrt(overlap) / (d - overlap)
    e100 = lattice_modulus(tmp_path, "hm100", 1e5, hm)
    assert e100 == pytest.approx(expected, rel=0.01), (e100, expected)
    assert lattice_modulus(tmp_path, "hm800", 8e5, hm) / e100 == pytest.approx(2.0, rel=0.015)
    linear = ["contact.young=3e9"]
    assert lattice_modulus(tmp_path, "lin800", 8e5, linear) / lattice_modulus(tmp_path, "lin100", 1e5, linear) == \
        pytest.approx(1.0, abs=0.005)


def test_resume_after_kill_is_bit_identical(tmp_path):
    extra = ['contact.rolling="kozicki"', "contact.restitution=0.5", "test.final_axial_strain=0.02",
             "output.checkpoint_every=0.002"]
    (ca, sa), _ = run(tmp_path / "whole", *extra)
    cut = tmp_path / "cut"
    proc = subprocess.Popen([GRAINLAB, "run", CONFIG, "--out", str(cut), "--quiet", "--threads", "1", *args(*extra)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=300)
    resumed = subprocess.run([GRAINLAB, "resume", str(cut), "--quiet"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert (tmp_path / "whole" / "timeseries.csv").read_text() == (cut / "timeseries.csv").read_text()
    cb, sb = read(cut)
    assert {k: v for k, v in sa.items() if k not in VOLATILE} == {k: v for k, v in sb.items() if k not in VOLATILE}
    assert ca["D_damping"][-1] > 0  # the dashpots dissipate


@pytest.mark.parametrize("setting,key,words", [
    ("contact.poisson=0.5", "contact.poisson", "[0, 0.5)"),
    ("contact.restitution=0", "contact.restitution", "(0, 1]"),
    ("contact.restitution=1.5", "contact.restitution", "(0, 1]"),
    ("contact.shear_modulus=-1", "contact.shear_modulus", "[1e3, 1e13]"),
    ('contact.rolling="moments"', "contact.rolling", '"none", "kozicki", "rolling-linear"'),
    ('sample.shape={type="ellipsoid", elongation=0.5}', "contact.model", "ellipsoid"),
    ("contact.rolling_friction=0.2", "contact.rolling_friction", "linear rolling resistance"),
])
def test_bad_input_exits_2_naming_the_key(tmp_path, setting, key, words):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *args(setting)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert key in proc.stderr and words in proc.stderr, proc.stderr
