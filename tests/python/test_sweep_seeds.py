"""Replicate seeds (`grainlab sweep --seeds N`, docs/interface.md "Replicate seeds"): N samples per
case, the seed the grid's innermost dimension, and sweep-stats.csv whose numbers are recomputed
here with numpy from the per-seed rows of sweep.csv (an independent computation)."""
import csv
import json
import os

import numpy as np

QUICK = ["--set", "sample.n_particles=60", "--set", "test.final_axial_strain=0.005", "--set",
         "sample.prep_friction_deg=10.0", "--set", "output.plots=false", "--jobs", "2", "--threads", "1", "--quiet"]


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_seeds_run_every_case_n_times_and_the_statistics_are_those_of_the_rows(grainlab, data_dir, tmp_path):
    out = tmp_path / "sweep"
    config = os.path.join(data_dir, "small-triaxial.toml")  # sample.seed = 7
    grainlab("sweep", config, "--vary", "contact.beta=0,0.15", "--seeds", "3", "--out", str(out), *QUICK, check=0)
    rows = rows_of(out / "sweep.csv")
    assert [(r["contact.beta"], r["sample.seed"]) for r in rows] == [
        (b, s) for b in ("0", "0.15") for s in ("7", "8", "9")]
    assert all(r["status"] == "completed" for r in rows)
    # Three seeds are three samples: their e0 and strengths differ.
    assert len({r["phi_peak_deg"] for r in rows[:3]}) == 3
    stats = rows_of(out / "sweep-stats.csv")
    assert [s["contact.beta"] for s in stats] == ["0", "0.15"]
    for s, group in zip(stats, (rows[:3], rows[3:])):
        assert s["seeds"] == "3" and s["seeds_completed"] == "3"
        for q in ("phi_peak_deg", "e0", "E50_MPa", "end_void_ratio", "psi_max_deg"):
            # A seed that did not measure the value (empty in sweep.csv) is left out and counted.
            x = np.array([float(r[q]) for r in group if r[q] != ""])
            assert s[q + "_n"] == str(len(x))
            if len(x) == 0:
                assert s[q + "_mean"] == ""
                continue
            # sweep.csv holds 8 significant digits of each seed's value; the statistics are of the
            # full values: agreement to that rounding.
            tol = 1e-7 * np.abs(x).max()
            assert abs(float(s[q + "_mean"]) - x.mean()) <= tol
            if len(x) >= 2:
                assert abs(float(s[q + "_std"]) - x.std(ddof=1)) <= 2 * tol
            assert float(s[q + "_min"]) == x.min() and float(s[q + "_max"]) == x.max()
        # Not measured in any seed (no critical state at 0.5 %): empty, n = 0, never 0.
        assert s["cs_q_over_p_mean"] == "" and s["cs_q_over_p_n"] == "0"
        assert float(s["critical_state_reached_mean"]) == 0.0
    md = (out / "sweep-stats.md").read_text()
    x = np.array([float(r["phi_peak_deg"]) for r in rows[:3]])
    assert f"{x.mean():.1f} ± {x.std(ddof=1):.1f}" in md
    assert "sample.seed 7 to 9" in md
    # The same command resumes: every case is kept.
    proc = grainlab("sweep", config, "--vary", "contact.beta=0,0.15", "--seeds", "3", "--out", str(out),
                    *QUICK[:-1], check=0)
    assert "6 of 6 cases completed earlier" in proc.stderr
    assert json.loads((out / "sweep.json").read_text())["seeds"] == 3


def test_seeds_alone_replicate_one_case_and_two_seeds_give_the_range(grainlab, data_dir, tmp_path):
    out = tmp_path / "alone"
    grainlab("sweep", os.path.join(data_dir, "small-triaxial.toml"), "--seeds", "2", "--set", "sample.seed=41",
             "--out", str(out), *QUICK, check=0)
    rows = rows_of(out / "sweep.csv")
    assert [r["sample.seed"] for r in rows] == ["41", "42"]
    x = sorted(float(r["phi_peak_deg"]) for r in rows)
    assert f"[{x[0]:.1f}, {x[1]:.1f}]" in (out / "sweep-stats.md").read_text()


def test_seeds_refused_where_they_cannot_apply(grainlab, data_dir, tmp_path):
    config = os.path.join(data_dir, "small-triaxial.toml")
    proc = grainlab("sweep", config, "--vary", "sample.seed=1,2", "--seeds", "3", "--out", str(tmp_path / "a"),
                    check=2)
    assert "sample.seed is varied too" in proc.stderr
    for bad in ("0", "1001", "x"):
        proc = grainlab("sweep", config, "--seeds", bad, "--vary", "contact.beta=0,1", "--out", str(tmp_path / "b"),
                        check=2)
        assert "--seeds" in proc.stderr
    proc = grainlab("sweep", config, "--out", str(tmp_path / "c"), check=2)
    assert "--seeds N" in proc.stderr and "--vary" in proc.stderr
    packing = tmp_path / "p.txt"
    grainlab("run", config, "--set", "sample.n_particles=60", "--set", "test.final_axial_strain=0.001",
             "--set", "sample.prep_friction_deg=10.0", "--set", "output.plots=false", "--out", str(tmp_path / "r"),
             "--threads", "1", "--quiet", check=0)
    proc = grainlab("sweep", config, "--seeds", "2", "--set", f"sample.packing=\"{tmp_path / 'r' / 'packing.txt'}\"",
                    "--out", str(tmp_path / "d"), check=2)
    assert "sample.packing" in proc.stderr and "seed cannot change" in proc.stderr
    assert not (tmp_path / "a").exists() and not (tmp_path / "d").exists()
