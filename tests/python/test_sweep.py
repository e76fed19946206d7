"""Sweeps: a grid of overrides runs as parallel processes into one comparison table; a failed
case is reported and does not stop the others."""
import csv
import json
import os


def test_sweep_grid_table_and_failed_case(grainlab, data_dir, tmp_path):
    out = tmp_path / "sweep"
    # The second time step is forced far above critical: that case blows up (exit 1).
    proc = grainlab("sweep", os.path.join(data_dir, "small-triaxial.toml"),
                    "--vary", "contact.beta=0,0.15", "--vary", "solver.dt=1e-7,4e-6",
                    "--set", "sample.n_particles=60", "--set", "test.final_axial_strain=0.005",
                    "--set", "solver.force_dt=true", "--set", "sample.prep_friction_deg=10.0",
                    "--jobs", "2", "--threads", "1", "--out", str(out), "--quiet")
    assert proc.returncode == 1, proc.stderr
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 4
    assert [(r["contact.beta"], r["solver.dt"]) for r in rows] == [
        ("0", "1e-7"), ("0", "4e-6"), ("0.15", "1e-7"), ("0.15", "4e-6")]
    for r in rows:
        if r["solver.dt"] == "1e-7":
            assert r["status"] == "completed"
            # The table reports what the case measured (8 significant digits of its summary).
            case = json.loads((out / r["case"] / "summary.json").read_text())
            assert abs(float(r["phi_peak_deg"]) - case["phi_peak_deg"]) <= 1e-7 * abs(case["phi_peak_deg"])
        else:
            assert r["status"].startswith("failed (exit 1)")
            assert r["phi_peak_deg"] == ""
    # Moments raise the strength of the completed cases.
    done = {r["contact.beta"]: float(r["phi_peak_deg"]) for r in rows if r["status"] == "completed"}
    assert done["0.15"] > done["0"]
    assert (out / "plots" / "q_eps1.png").exists()


def test_sweep_bad_value_is_input_error(grainlab, data_dir, tmp_path):
    proc = grainlab("sweep", os.path.join(data_dir, "small-triaxial.toml"), "--vary", "contact.friction_deg=30,95",
                    "--out", str(tmp_path / "s"), check=2)
    assert "contact.friction_deg" in proc.stderr and "95" in proc.stderr
