"""test.type = "stress-path" (issue 24): a table of per-axis stress or strain targets along a
progress variable s, followed by the boundary. End to end through the CLI on the small soft sample
of test_lab_tests.py: the records follow the table (strain targets exactly, stress targets within
the servo's lag the summary reports), a strain-controlled axial path with the lateral stresses held
is the triaxial test, the inline form that config.resolved.toml keeps resumes bit-identically after
a kill with the path file gone, a target beyond the sample's strength stops the test with a warning,
and bad paths exit 2 naming the key (and the line). Against analytic numbers:
tests/unit/test_stress_path.cpp (the FCC lattice)."""
import json
import subprocess

import numpy as np
import pytest

from conftest import GRAINLAB, kill_after_second_checkpoint
from test_lab_tests import CONFIG, VOLATILE, read, sets

HEADER = "s,xx,xx_control,yy,yy_control,zz,zz_control\n"
# Constant p = 100 kPa to q = 60 kPa, back to isotropic, then 0.3 % axial strain, lateral 100 kPa.
THREE_SEGMENTS = HEADER + ("0.002,80e3,stress,80e3,stress,140e3,stress\n"
                           "0.004,100e3,stress,100e3,stress,100e3,stress\n"
                           "0.006,100e3,stress,100e3,stress,0.003,strain\n")


def write_path(tmp_path, text, name="path.csv"):
    f = tmp_path / name
    f.write_text(text)
    return f


def run_path(tmp_path, name, path_file, *extra, check=0):
    out = tmp_path / name
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(out), "--quiet", "--threads", "1",
                           *sets('test.type="stress-path"', f'test.path={{file="{path_file}"}}',
                                 "sample.e0_tolerance=1.0", *extra)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == check, proc.stderr
    return (read(out) if check == 0 else None), proc


def test_the_records_follow_the_table(tmp_path):
    (c, s), _ = run_path(tmp_path, "three", write_path(tmp_path, THREE_SEGMENTS))
    assert s["test"] == "stress-path" and s["path_completed"] is True and s["path_points"] == 3
    assert c["s"][-1] == pytest.approx(0.006) and list(np.unique(c["segment"])) == [1, 2, 3]
    lag = s["path_stress_deviation_max"]
    assert 0.0 < lag < 0.5
    # Segment 1 at its end: sigma_zz = 140 kPa, sigma_xx = sigma_yy = 80 kPa, p = 100 kPa held on
    # the way (all within the servo's lag of the stress targets, a fraction of p0 = 100 kPa).
    end1 = np.argmin(np.abs(c["s"] - 0.002))
    assert c["sigma1"][end1] == pytest.approx(140e3, abs=0.05e5)
    assert c["sigma2"][end1] == pytest.approx(80e3, abs=0.05e5)
    first = c["segment"] == 1
    assert np.abs(c["p"][first] - 100e3).max() < lag * 100e3 + 1e3
    # Segments 1-2 are stress-controlled below the strength: small strains. Segment 3: eps_zz
    # follows s exactly (dead-beat drive), on the straight line from where it stood at s = 0.004
    # to 0.003 at s = 0.006.
    third = c["segment"] == 3
    slope, intercept = np.polyfit(c["s"][third], c["eps1"][third], 1)
    assert np.abs(slope * c["s"][third] + intercept - c["eps1"][third]).max() < 1e-9
    assert slope * 0.006 + intercept == pytest.approx(0.003, abs=1e-9)
    assert c["eps1"][-1] == pytest.approx(0.003, abs=1e-9)
    assert abs(c["eps1"][first]).max() < 1e-3


def test_a_strain_path_with_lateral_stresses_held_is_the_triaxial_test(tmp_path):
    """The same sample sheared to 1 % by the triaxial test and by a one-segment path (eps_zz to
    0.01 at the same rate, sigma_xx = sigma_yy = p0): the curves agree (rounding of the two drives
    differs, so not bit for bit)."""
    (c, s), _ = run_path(tmp_path, "path", write_path(tmp_path, HEADER + "0.01,100e3,stress,100e3,stress,0.01,strain\n"))
    tri = tmp_path / "tri"
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(tri), "--quiet", "--threads", "1",
                           *sets("test.final_axial_strain=0.01", "sample.e0_tolerance=1.0")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    t, _ = read(tri)
    for eps in (0.002, 0.005, 0.01):
        qa = np.interp(eps, c["eps1"], c["q"])
        qb = np.interp(eps, t["eps1"], t["q"])
        assert qa == pytest.approx(qb, rel=0.05), eps
        va = np.interp(eps, c["eps1"], c["eps_v"])
        vb = np.interp(eps, t["eps1"], t["eps_v"])
        assert va == pytest.approx(vb, abs=0.1 * abs(vb) + 2e-4), eps


def test_a_target_beyond_the_strength_stops_the_path(tmp_path):
    # sigma_zz to 60 times the lateral stress: no sand carries it; the test stops at 2 % strain.
    (c, s), _ = run_path(tmp_path, "fail", write_path(tmp_path, HEADER + "0.02,20e3,stress,20e3,stress,1.2e6,stress\n"),
                         "test.final_axial_strain=0.02")
    assert s["path_completed"] is False and s["status"] == "completed"
    assert s["path_s_reached"] < 0.02
    assert any("stress path stopped" in w for w in s["warnings"])
    assert max(abs(c["eps1"][-1]), abs(c["eps2"][-1]), abs(c["eps3"][-1])) >= 0.02 - 1e-3


def test_resume_is_bit_identical_with_the_path_file_gone(tmp_path):
    f = write_path(tmp_path, THREE_SEGMENTS)
    extra = ["output.checkpoint_every=2e-4"]
    (a, sa), _ = run_path(tmp_path, "whole", f, *extra)
    cut = tmp_path / "cut"
    proc = subprocess.Popen([GRAINLAB, "run", CONFIG, "--out", str(cut), "--quiet", "--threads", "1",
                             *sets('test.type="stress-path"', f'test.path={{file="{f}"}}', "sample.e0_tolerance=1.0",
                                   *extra)])
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=300)
    f.unlink()  # the resolved config keeps the points inline
    resumed = subprocess.run([GRAINLAB, "resume", str(cut), "--quiet"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert (tmp_path / "whole" / "timeseries.csv").read_text() == (cut / "timeseries.csv").read_text()
    sb = json.loads((cut / "summary.json").read_text())
    assert {k: v for k, v in sa.items() if k not in VOLATILE} == {k: v for k, v in sb.items() if k not in VOLATILE}


def test_the_inline_form_is_the_same_path(tmp_path):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets(
        'test.type="stress-path"',
        'test.path={points=[[0.002, 80e3, 80e3, 140e3], [0.004, 1e5, 1e5, 0.001]], '
        'controls=[["stress","stress","stress"], ["stress","stress","strain"]]}')],
        capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "points = [" in proc.stdout and "'strain'" in proc.stdout


@pytest.mark.parametrize("path,key,words", [
    ('{file="missing.csv"}', "test.path.file", ["file not found"]),
    ('"path.csv"', "test.path", ["inline table"]),
    ('{points=[[0.01, 1e5, 1e5]], controls=[["stress","stress","stress"]]}', "test.path.points[0]", ["four"]),
    ('{points=[[0.01, 1e5, 1e5, 1e5]], controls=[["stress","stress","sress"]]}', "test.path.controls[0]",
     ['"stress" or "strain"']),
    ('{points=[[0.01, 1e5, 1e5, 1e5]]}', "test.path.controls", ["one [xx, yy, zz]"]),
    ('{points=[[0.01, -1e5, 1e5, 1e5]], controls=[["stress","stress","stress"]]}', "test.path.points[0]", ["no tension"]),
    ('{points=[[0.02, 1e5, 1e5, 1e5], [0.01, 1e5, 1e5, 1e5]], controls=[["stress","stress","stress"], '
     '["stress","stress","stress"]]}', "test.path.points[1]", ["above the previous"]),
    ('{file="x.csv", colour="red"}', "test.path.colour", ["unknown"]),
])
def test_bad_paths_are_refused(tmp_path, path, key, words):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets('test.type="stress-path"', f"test.path={path}")],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and key in line, line
    for w in words:
        assert w in line, f"{w!r} not in {line}"


def test_a_bad_line_of_the_file_is_named(tmp_path):
    f = write_path(tmp_path, HEADER + "0.01,1e5,stress,1e5,stress,1e5,stress\n0.02,1e5,stress,abc,stress,1e5,stress\n")
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets('test.type="stress-path"', f'test.path={{file="{f}"}}')],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "test.path.file" in proc.stderr and "line 3" in proc.stderr and '"abc"' in proc.stderr, proc.stderr


def test_a_path_needs_its_table_and_other_tests_ignore_it(tmp_path):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets('test.type="stress-path"')],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "test.path" in proc.stderr and "needs its table" in proc.stderr, proc.stderr
    f = write_path(tmp_path, THREE_SEGMENTS)
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets(f'test.path={{file="{f}"}}')],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "warning: test.path = " in proc.stderr and "is ignored" in proc.stderr
