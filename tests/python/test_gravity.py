"""sample.gravity and sample.method = "deposition" (issue 27 §2) end to end through the CLI: a
deposited sample is deterministic for a seed and thread count, prefers vertical contacts, reports
its rain and settling; gravity on a triaxial test books its work (W_gravity) and keeps the energy
ledger closed; bad input exits 2 naming the key. Statics and the energy of single spheres and a
column under gravity against hand numbers: tests/unit/test_gravity.cpp."""
import re
import subprocess

import numpy as np
import pytest

from conftest import GRAINLAB
from test_lab_tests import CONFIG, read

DEPOSIT = ["sample.n_particles=150", 'sample.grading={type="uniform", d_min=4e-3, d_max=6e-3}',
           'sample.method="deposition"', "sample.drop_height=0.01", 'test.type="isotropic"', "sample.prep_friction_deg=30",
           "output.plots=false", "output.vtk_every_strain=0", "output.save_packing=true",
           # No small-strain probe: on this loose bed its lateral servo does not come back within 1 %
           # of the tiny axial increment and ran its 2e6-step cap (50 s of a 51 s run; not what is
           # tested here).
           "test.probe_strain=0"]


def args(extra):
    return [a for s in extra for a in ("--set", s)]


def run(out, *extra, base=DEPOSIT, check=0):
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(out), "--quiet", "--threads", "1", *args(list(base) + list(extra))],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == check, proc.stderr
    return (read(out) if check == 0 else None), proc


def test_deposition_is_deterministic_anisotropic_and_reported(tmp_path):
    (c, s), _ = run(tmp_path / "a")
    (_, s2), _ = run(tmp_path / "b")
    assert (tmp_path / "a" / "timeseries.csv").read_bytes() == (tmp_path / "b" / "timeseries.csv").read_bytes()
    assert (tmp_path / "a" / "packing.txt").read_bytes() == (tmp_path / "b" / "packing.txt").read_bytes()
    assert s["preparation_method"] == "deposition"
    d = s["deposition"]
    assert d["drop_height"] == 0.01 and 0 < d["cloud_solid_fraction"] < 0.5
    # The settled bed is looser than the consolidated sample, and both are loose.
    assert d["settled_void_ratio"] > s["e0"] > 0.6
    assert d["bed_height"] > 0 and d["gravity_work"] > 0 and d["steps"] > 0
    # Vertical contacts are preferred (rained grains rest on those below).
    f = s["fabric_after_preparation"]
    assert d["settled_a_r_zz"] > 0.1 and f["a_r_zz"] > 0
    assert "W_gravity" in c and np.all(np.isfinite(c["W_gravity"]))
    # The resolved config records the default gravity of the method.
    resolved = (tmp_path / "a" / "config.resolved.toml").read_text()
    assert re.search(r"^gravity = \[ 0\.0, 0\.0, -9\.81\d* \]$", resolved, re.M), resolved


def test_gravity_on_a_triaxial_books_its_work(tmp_path):
    # Strong gravity (10 g) on a soft sample, so that its work is visible beside the boundary's.
    (c, s), _ = run(tmp_path / "g", "sample.gravity=[0, 0, -98.1]", "sample.n_particles=150", "contact.young=3e8",
                    "test.final_axial_strain=0.01", "output.plots=false", "output.vtk_every_strain=0", base=[])
    assert s["status"] == "completed"
    # The platens squeeze the sample down onto the fixed pedestal: the grains sink, gravity works.
    assert c["W_gravity"][-1] > 0
    assert s["energy_residual_max"] is not None and s["energy_residual_max"] < 0.02
    # The small-strain probe settles under gravity: its reference state is judged on the platen that
    # holds p, not on the mean axial stress (which carries the weight on the pedestal besides p and
    # never came to p: the probe ran its 2e6-step cap and reported no E0).
    assert s["E0_probe"]["settled"] is True and s["E0_probe"]["steps"] < 100000, s["E0_probe"]
    assert s["E0_MPa"] > 0 and 0 < s["nu0"] < 0.5
    # Without gravity the column is absent.
    (c0, _), _ = run(tmp_path / "n", "sample.n_particles=150", "contact.young=3e8", "test.final_axial_strain=0.005",
                     "output.plots=false", "output.vtk_every_strain=0", base=[])
    assert "W_gravity" not in c0


@pytest.mark.parametrize("extra,key", [
    (['test.boundary="periodic"', "sample.gravity=[0, 0, -9.81]"], "sample.gravity"),
    (['test.boundary="periodic"', 'sample.method="deposition"'], "sample.gravity"),
    (['sample.method="deposition"', "sample.gravity=[0, -9.81, 0]"], "sample.gravity"),
    (["sample.gravity=[0, -9.81]"], "sample.gravity"),
    (["sample.gravity=[0, 0, -2000]"], "sample.gravity"),
    (['sample.gravity=[0, 0, "down"]'], "sample.gravity"),
    (["sample.drop_height=0.1"], "sample.drop_height"),
    (['sample.method="deposition"', "sample.drop_height=-1"], "sample.drop_height"),
    (['sample.method="deposition"', 'sample.shape={type="ellipsoid", elongation=0.7}'], "sample.method"),
])
def test_bad_gravity_input_exits_2_naming_the_key(tmp_path, extra, key):
    _, proc = run(tmp_path / "bad", *extra, base=[], check=2)
    assert key in proc.stderr and any(w in proc.stderr for w in ("allowed", "must", "only used")), proc.stderr
    assert not (tmp_path / "bad" / "summary.json").exists()
