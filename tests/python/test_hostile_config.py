"""Issue 28, part B: config and input-file validation. Each hostile case must exit 2 with one line
naming the key (or file and line), the value and what is allowed, in `check` as in `run`."""
import os
import subprocess
import tomllib

import pytest

from conftest import GRAINLAB, TINY_CONFIG

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def run(*args, cwd=None):
    return subprocess.run([GRAINLAB, *args], capture_output=True, text=True, timeout=600, cwd=cwd)


@pytest.fixture
def base(tmp_path):
    path = tmp_path / "base.toml"
    path.write_text(TINY_CONFIG + f'dir = "{tmp_path / "out"}"\n')
    return path


def refused(proc, *words):
    assert proc.returncode == 2, f"exit {proc.returncode}\n{proc.stdout}\n{proc.stderr}"
    line = proc.stderr.strip()
    assert "\n" not in line, line
    for w in words:
        assert w in line, f"{w!r} not in: {line}"
    return line


def both(base, sets, *words):
    """`check` and `run` refuse the same, before anything is written."""
    args = [a for s in sets for a in ("--set", s)]
    refused(run("check", str(base), *args), *words)
    refused(run("run", str(base), *args, "--quiet"), *words)
    assert not os.path.exists(base.parent / "out" / "summary.json")


# 1. Derived parameters that overflow or vanish.
def test_rolling_friction_overflow_names_file_line_and_keys(base, tmp_path):
    csv = tmp_path / "psi.csv"
    csv.write_text("sphericity\n0.9\n1e-300\n")
    both(base, ["contact.model=rolling-linear", f'contact.sphericity={{ file = "{csv}", c = 1e308, k = -200 }}'],
         "psi.csv", "line 2", "mu_r = c psi^k", "contact.sphericity.c", "contact.sphericity.k")


# 2. Headers only where the format says so.
@pytest.mark.parametrize("first", ["0.003abc", "3e-3m", "d50"])
def test_grading_list_first_line_with_a_digit_is_data(base, tmp_path, first):
    lst = tmp_path / "d.txt"
    lst.write_text(f"{first}\n0.004\n0.005\n")
    both(base, [f'sample.grading={{ type = "list", file = "{lst}" }}'], "d.txt", "line 1", first)


def test_grading_list_header_without_digit_and_comments_accepted(base, tmp_path, grainlab):
    lst = tmp_path / "d.txt"
    lst.write_text("# sieve data\ndiameter_m\n0.004\n0.005\n")
    grainlab("check", str(base), "--set", f'sample.grading={{ type = "list", file = "{lst}" }}', check=0)


# 3. The resolved config of a run from a packing records the packing's count and grading.
def test_resolved_config_records_the_packing(base, tmp_path, grainlab):
    first = tmp_path / "first"
    grainlab("run", str(base), "--out", str(first), "--quiet", check=0)
    packing = first / "packing.txt"
    cfg = tmp_path / "from-packing.toml"
    cfg.write_text(TINY_CONFIG.replace('grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }\n', "")
                   .replace("e0 = 0.7\n", "").replace("prep_friction_deg = 0.0\n", "").replace("n_particles = 100\n", "")
                   .replace("[sample]\n", f'[sample]\npacking = "{packing}"\n'))
    out = tmp_path / "second"
    printed = tomllib.loads(grainlab("check", str(cfg), "--set", f"output.dir={out}", check=0).stdout)
    assert printed["sample"]["n_particles"] == 100 and printed["sample"]["grading"] == {"type": "packing"}
    grainlab("run", str(cfg), "--out", str(out), "--quiet", check=0)
    resolved = tomllib.loads((out / "config.resolved.toml").read_text())
    assert resolved["sample"]["n_particles"] == 100
    assert resolved["sample"]["grading"] == {"type": "packing"}
    assert "e0" not in resolved["sample"] and "method" not in resolved["sample"]
    # The resolved config is itself a valid config.
    grainlab("check", str(out / "config.resolved.toml"), "--set", f"output.dir={tmp_path / 'third'}", check=0)
    # A count that contradicts the packing is ignored with a warning (the packing brings its own).
    proc = grainlab("check", str(cfg), "--set", "sample.n_particles=99", check=0)
    assert "warning: sample.n_particles = 99 is ignored" in proc.stderr and "holds 100" in proc.stderr
    assert tomllib.loads(proc.stdout)["sample"]["n_particles"] == 100
    # Preparation keys beside a packing (a config reused with --set sample.packing=...) are ignored
    # with a warning, and not recorded.
    proc = grainlab("check", str(cfg), "--set", "sample.e0=0.7", "--set", f"output.dir={out}", check=0)
    assert "warning: sample.e0 = 0." in proc.stderr and "sample.packing" in proc.stderr
    assert "e0" not in tomllib.loads(proc.stdout)["sample"]


# 4. --set paths are relative to the working directory, config paths to the config's folder.
def test_set_paths_relative_to_working_directory(base, tmp_path, grainlab):
    (tmp_path / "cfgdir").mkdir()
    (tmp_path / "cwd").mkdir()
    (tmp_path / "cfgdir" / "d.txt").write_text("0.004\n0.005\n")
    (tmp_path / "cwd" / "d.txt").write_text("0.005\n0.006\n")
    cfg = tmp_path / "cfgdir" / "c.toml"
    uniform = 'grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }'
    cfg.write_text(base.read_text().replace(uniform, 'grading = { type = "list", file = "d.txt" }'))
    printed = tomllib.loads(grainlab("check", str(cfg), check=0).stdout)
    assert printed["sample"]["grading"]["file"] == str(tmp_path / "cfgdir" / "d.txt")
    proc = subprocess.run([GRAINLAB, "check", str(cfg), "--set", "sample.grading.file=d.txt"], capture_output=True,
                          text=True, cwd=tmp_path / "cwd")
    assert proc.returncode == 0, proc.stderr
    assert tomllib.loads(proc.stdout)["sample"]["grading"]["file"] == str(tmp_path / "cwd" / "d.txt")
    # No fallback: a config's relative path that is not beside it is not looked up in the working directory.
    (tmp_path / "cwd" / "only.txt").write_text("0.005\n")
    cfg.write_text(base.read_text().replace(uniform, 'grading = { type = "list", file = "only.txt" }'))
    refused(run("check", str(cfg), cwd=tmp_path / "cwd"), "file not found", "config's folder")


# 5. Settings that cannot apply.
@pytest.mark.parametrize("sets,words", [
    (['sample.shape={ type = "sphere", elongation = 0.7 }'], ["sample.shape.elongation", "sample.shape.type"]),
    (["test.boundary=periodic", "contact.wall_friction_deg=10", "sample.n_particles=400"],
     ["contact.wall_friction_deg", "test.boundary"]),
    (["sample.method=lattice", "sample.n_particles=125"], ["sample.grading", "lattice"]),
    (["contact.model=rolling-linear", "contact.beta=0.2"], ["contact.beta", "contact.model"]),
    (["contact.model=rolling-linear", "contact.eta=0.5"], ["contact.eta", "contact.model"]),
    (["solver.force_dt=true"], ["solver.force_dt", "solver.dt"]),
    (["sample.growth_rate=1e-5"], ["sample.growth_rate", "sample.method"]),
    (["test.loop_rest=true"], ["test.loop_rest", "test.unload_reload_at"]),
    (["contact.kn=1e5"], ["contact.young", "contact.kn"]),
    (["solver.viscous_damping=100", "solver.damping=0.3"], ["solver.damping", "solver.viscous_damping"]),
])
def test_settings_that_cannot_apply(base, sets, words):
    if "contact.kn=1e5" in sets:
        sets = sets + ["contact.young=30e9"]
    line = refused(run("check", str(base), *[a for s in sets for a in ("--set", s)]), *words)
    assert "cannot apply" in line or "lattice" in line


@pytest.mark.parametrize("sets,key", [
    (["test.b=0.5"], "test.b"),
    (["test.final_shear_strain=0.3"], "test.final_shear_strain"),
    (['test.type="isotropic"'], "test.axial_strain_rate"),
])
def test_keys_of_another_test_type_warn(base, grainlab, sets, key):
    """A config of one test reused for another (--set test.type=...) keeps the other test's keys:
    ignored, with a warning that names the key and test.type (issue 28: they were ignored silently)."""
    proc = grainlab("check", str(base), *[a for s in sets for a in ("--set", s)], check=0)
    assert f"warning: {key} = " in proc.stderr and "test.type" in proc.stderr and "is ignored" in proc.stderr
    assert key.split(".")[1] not in tomllib.loads(proc.stdout)["test"]


def test_preparation_target_ignored_by_the_method_warns(base, grainlab):
    proc = grainlab("check", str(base), "--set", "sample.method=lattice", "--set", "sample.n_particles=125", "--set",
                    'sample.grading={ type = "uniform", d_min = 5e-3, d_max = 5e-3 }', check=0)
    assert "warning: sample.e0 = " in proc.stderr and "sample.method" in proc.stderr
    assert "e0" not in tomllib.loads(proc.stdout)["sample"]


def test_every_shipped_config_passes_check_and_round_trips(grainlab, tmp_path):
    names = [l.split()[0] for l in grainlab("presets", check=0).stdout.splitlines() if l.strip()]
    sources = [f"preset:{n}" for n in names] + [os.path.join(ROOT, "tests", "data", f)
                                                for f in ("small-triaxial.toml", "calibrate-small.toml")]
    for source in sources:
        printed = grainlab("check", source, "--set", f"output.dir={tmp_path / 'x'}", check=0).stdout
        again = tmp_path / "resolved.toml"
        again.write_text(printed)
        assert grainlab("check", str(again), check=0).stdout == printed, source


def test_e0_missed_with_fixed_friction_warns(base, grainlab, tmp_path):
    out = tmp_path / "w"
    proc = grainlab("run", str(base), "--set", "sample.e0=2.0", "--set", "sample.e0_tolerance=0.01", "--out", str(out),
                    "--quiet", check=0)
    assert "warning" in proc.stderr and "sample.e0 = 2" in proc.stderr
    import json
    summary = json.loads((out / "summary.json").read_text())
    assert summary["e0_within_tolerance"] is False and any("sample.e0" in w for w in summary["warnings"])


# 6. Subnormal numbers and practical lower bounds.
@pytest.mark.parametrize("key,value,words", [
    ("test.final_axial_strain", "1e-320", ["subnormal"]),
    ("test.final_axial_strain", "1e-300", ["[1e-4, 0.5]"]),
    ("test.axial_strain_rate", "1e-320", ["subnormal"]),
    ("contact.poisson", "1e-310", ["subnormal"]),
    ("solver.dt", "5e-324", ["subnormal"]),
    ("contact.young", "1e-300", ["[1e3, 1e15]"]),
    ("test.confining_pressure", "1e-300", ["[1, 1e10]"]),
    ("sample.density", "1e-300", ["[1, 1e6]"]),
])
def test_subnormal_and_tiny_values_refused(base, key, value, words):
    refused(run("check", str(base), "--set", f"{key}={value}"), key, *words)


# 7. Bad input that used to surface as "numerical instability".
def test_gradings_of_absurd_size_refused(base):
    refused(run("check", str(base), "--set", 'sample.grading={ type = "uniform", d_min = 1e300, d_max = 1e300 }'),
            "sample.grading.d_min", "[1e-06, 10] m")
    refused(run("check", str(base), "--set", 'sample.grading={ type = "uniform", d_min = 1e-300, d_max = 1e-3 }'),
            "sample.grading.d_min")


def packing_text(rows, walls="0 0.02 0 0.02 0 0.02"):
    lines = ["# grainlab-packing 2", "# program grainlab test", "# comment c", "# boundary walls", f"# walls {walls}",
             f"# particles {len(rows)}", "# columns id shape a b c x y z qw qx qy qz"]
    lines += [f"{i} sphere {r} {r} {r} {x} {y} {z} 1 0 0 0" for i, (r, x, y, z) in enumerate(rows)]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("rows,words", [
    ([(0.002, 0.005, 0.005, 0.005), (0.002, 0.005, 0.005, 0.005)], ["id 0 and id 1", "coincident"]),
    ([(0.002, 0.005, 0.005, 0.005), (0.002, 0.007, 0.005, 0.005)], ["id 0 and id 1", "overlap"]),
    ([(0.002, 0.005, 0.005, 0.005), (0.015, 0.01, 0.01, 0.01)], ["id 1", "smaller than the box"]),
])
def test_bad_packings_fail_check(base, tmp_path, rows, words):
    pk = tmp_path / "p.txt"
    pk.write_text(packing_text(rows))
    cfg = tmp_path / "pk.toml"
    cfg.write_text(f'[sample]\npacking = "{pk}"\n[test]\nfinal_axial_strain = 0.01\n[solver]\nthreads = 1\n'
                   f'[output]\ndir = "{tmp_path / "out"}"\nplots = false\n')
    refused(run("check", str(cfg)), "sample.packing", *words)


@pytest.mark.parametrize("overlap,accepted", [(0.12, True), (0.45, True), (0.6, False)])
def test_soft_contact_overlaps_are_accepted_deep_ones_refused(tmp_path, grainlab, overlap, accepted):
    """A packing of soft contacts in equilibrium overlaps by more than a tenth of a radius ([O]'s
    kappa = 25 grown spheres: 0.12, which grainlab once refused in its own packing file); beyond
    half the smaller radius it is refused, naming both grains."""
    r = 0.002
    rows = [(r, 0.005, 0.005, 0.005), (r, 0.005 + 2 * r - overlap * r, 0.005, 0.005)]
    pk = tmp_path / "p.txt"
    pk.write_text(packing_text(rows))
    cfg = tmp_path / "pk.toml"
    cfg.write_text(f'[sample]\npacking = "{pk}"\n[test]\nfinal_axial_strain = 0.01\n[solver]\nthreads = 1\n'
                   f'[output]\ndir = "{tmp_path / "out"}"\nplots = false\n')
    if accepted:
        grainlab("check", str(cfg), check=0)
    else:
        refused(run("check", str(cfg)), "sample.packing", "id 0 and id 1", "overlap", "0.5 of the smaller radius")


def test_packing_overlap_check_is_linear(tmp_path, grainlab):
    """20 000 grains on a lattice touching their neighbours (overlap 1 %): accepted quickly."""
    n, r = 27, 0.001
    rows = [(r, 0.0001 + r + i * 1.98 * r, 0.0001 + r + j * 1.98 * r, 0.0001 + r + k * 1.98 * r)
            for i in range(n) for j in range(n) for k in range(n)]
    side = 0.0002 + 2 * r + (n - 1) * 1.98 * r
    pk = tmp_path / "p.txt"
    pk.write_text(packing_text(rows, walls=f"0 {side} 0 {side} 0 {side}"))
    cfg = tmp_path / "pk.toml"
    cfg.write_text(f'[sample]\npacking = "{pk}"\n[test]\nfinal_axial_strain = 0.01\n[solver]\nthreads = 1\n'
                   f'[output]\ndir = "{tmp_path / "out"}"\nplots = false\n')
    grainlab("check", str(cfg), check=0, timeout=60)


# 8. check makes the run's time-step check.
def test_check_refuses_dt_above_critical(base):
    both(base, ["solver.dt=1e-3"], "solver.dt = 0.001", "critical time step")


# 9. Unknown keys first, with a suggestion.
def test_typo_reported_before_cross_key_checks(base):
    line = refused(run("check", str(base), "--set", "sample.n_partciles=2000", "--set", "sample.method=lattice"),
                   "sample.n_partciles", "unknown key", "did you mean sample.n_particles")
    assert "cube" not in line
    refused(run("check", str(base), "--set", "sample.young=1e9"), "did you mean contact.young")
    refused(run("check", str(base), "--set", "sampel.n_particles=10"), "unknown section", "did you mean [sample]")
    refused(run("check", str(base), "--set", 'sample.grading={ type = "uniform", d_mim = 1e-3, d_max = 2e-3 }'),
            "sample.grading.d_mim", "did you mean sample.grading.d_min")


# 11. Up-front estimate of the test's steps.
def test_steps_estimate_refuses_a_test_that_cannot_finish(base):
    both(base, ["test.axial_strain_rate=1e-9"], "test.axial_strain_rate", "steps", "solver.max_steps")


# 12. Memory bounded before it is committed.
def test_memory_estimate_refuses_before_allocating(base):
    pages, size = os.sysconf("SC_PHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
    if 50_000_000 * 2048 < pages * size:
        pytest.skip("a machine with more than 100 GB of memory")
    proc = subprocess.run(["/usr/bin/time", "-f", "%M", GRAINLAB, "check", str(base), "--set", "sample.n_particles=50000000"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "sample.n_particles = 50000000" in proc.stderr and "GiB" in proc.stderr
    assert int(proc.stderr.strip().splitlines()[-1]) < 200_000  # KB: refused before allocating
