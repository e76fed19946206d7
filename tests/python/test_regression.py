"""Regression: a small whole triaxial test, with and without contact moments, against stored
reference numbers and stated tolerances (tests/data/regression_reference.json)."""
import json
import os

import pytest

with open(os.path.join(os.path.dirname(__file__), "..", "data", "regression_reference.json")) as f:
    REFERENCE = json.load(f)["cases"]


@pytest.mark.parametrize("case", sorted(REFERENCE))
def test_small_triaxial_matches_reference(grainlab, data_dir, tmp_path, case):
    spec = REFERENCE[case]
    args = []
    for s in spec["set"]:
        args += ["--set", s]
    out = tmp_path / case
    grainlab("run", os.path.join(data_dir, "small-triaxial.toml"), "--out", str(out), "--quiet",
             *args, check=0, timeout=300)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    failures = []
    for key, (value, tolerance) in spec["expect"].items():
        if abs(summary[key] - value) > tolerance:
            failures.append(f"{key} = {summary[key]:.4g}, reference {value} +- {tolerance}")
    assert not failures, "; ".join(failures)
    # Quasi-static and well-posed: the inertial number stayed below 1e-3; the isotropic state before
    # shearing met the equilibrium criteria.
    assert summary["inertial_number"] < 1e-3
    assert summary["isotropic_state"]["unbalanced"] < 0.01
    for wall, contact in zip(summary["isotropic_state"]["wall_stress"],
                             summary["isotropic_state"]["contact_stress"]):
        assert abs(wall - 100e3) < 1e3
        assert abs(contact / wall - 1) < 0.02
    # The outputs a user relies on are there.
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    for column in "step,time,eps1,eps_v,sigma1,sigma2,sigma3,q,p,e,phi_deg,Z,unbalanced".split(","):
        assert column in header
    assert (out / "config.resolved.toml").exists()
