"""`grainlab bench --packing`: any packing a run saved (walls or cell, spheres or ellipsoids) is timed
as it is, held at the config's pressure; bad combinations are refused with exit 2."""
import json
import os


def test_bench_times_a_saved_periodic_ellipsoid_packing(grainlab, tmp_path):
    out = tmp_path / "r"
    grainlab("run", "preset:ouadfel-spheroids", "--out", str(out), "--threads", "1", "--quiet",
             "--set", "sample.n_particles=125", "--set", "test.final_axial_strain=0.002",
             "--set", "output.plots=false", "--set", "output.vtk_every_strain=0", check=0)
    proc = grainlab("bench", "--packing", str(out / "packing.txt"), "--config", "preset:ouadfel-spheroids",
                    "--steps", "50", "--json", check=0)
    j = json.loads(proc.stdout)
    assert j["scene"] == "packing" and j["boundary"] == "periodic"
    assert j["n_particles"] == 125 and j["n_ellipsoids"] == 125
    # The grown sample stays a jammed skeleton under the config's law (not exploded, not apart).
    assert j["coordination"] > 6.0
    assert j["particle_steps_per_s"] > 0


def test_bench_refuses_config_without_packing_and_a_missing_packing(grainlab, tmp_path):
    proc = grainlab("bench", "--config", "preset:ouadfel-spheroids", "--steps", "1", check=2)
    assert "--config" in proc.stderr and "--packing" in proc.stderr
    proc = grainlab("bench", "--packing", str(tmp_path / "none.txt"), "--steps", "1", check=2)
    assert "none.txt" in proc.stderr
