"""What a summary reports is what was simulated (issue 16): a packing file brings its own number of
particles and no preparation friction; README describes the energy sums as the code does them."""
import json
import os
import re
import subprocess

from conftest import GRAINLAB

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

ISOTROPIC = """\
[sample]
n_particles = 100
grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }
e0 = 0.7
seed = 3
prep_friction_deg = 4.0

[test]
type = "isotropic"
confining_pressure = 100.0e3

[solver]
threads = 1

[output]
plots = false
"""


def run(*args):
    proc = subprocess.run([GRAINLAB, *args], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc


def test_packing_start_reports_its_own_particles_and_no_preparation_friction(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(ISOTROPIC)
    run("run", str(cfg), "--out", str(tmp_path / "prepared"), "--quiet")
    prepared = json.loads((tmp_path / "prepared" / "summary.json").read_text())
    assert prepared["n_particles"] == 100
    assert prepared["prep_friction_deg"] == 4.0  # the friction the sample was compacted with
    # The same packing with a config that asks for 2000 spheres: the packing's 100 are simulated.
    packing = tmp_path / "prepared" / "packing.txt"
    run("run", str(cfg), "--out", str(tmp_path / "packed"), "--quiet", "--set", "sample.n_particles=2000",
        "--set", f'sample.packing="{packing}"')
    s = json.loads((tmp_path / "packed" / "summary.json").read_text())
    assert s["n_particles"] == 100
    assert s["prep_friction_deg"] is None
    rate = s["steps"] * 100 / s["wall_seconds"]
    assert abs(s["particle_steps_per_s"] / rate - 1.0) < 1e-3, (s["particle_steps_per_s"], rate)


def test_readme_says_energy_sums_use_fixed_chunks():
    readme = open(os.path.join(ROOT, "README.md")).read()
    assert "per-thread partials" not in readme
    sentence = next(line for line in readme.splitlines() if "energy sums" in line)
    assert "fixed chunks" in sentence
    # ... as src/core/parallel.hpp implements them: a chunk size that is a constant, not a thread count.
    header = open(os.path.join(ROOT, "src", "core", "parallel.hpp")).read()
    assert re.search(r"static constexpr std::size_t kChunk = \d+;", header)
