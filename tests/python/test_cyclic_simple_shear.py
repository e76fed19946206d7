"""test.type = "cyclic-simple-shear" (issue 24): strain-controlled cycles of gamma in the periodic
cell at a list of amplitudes; the secant shear modulus and the damping ratio per amplitude. End to
end through the CLI on the small soft sample of test_lab_tests.py: the summary's G and damping
ratio recomputed here from the recorded loop (a coarser sampling than the protocol's every-step
integral), G/Gmax falling and damping rising with the amplitude as a sand's do, Gmax against the
small-strain probe's E0/(2(1 + nu0)), the undrained volume held, resume bit-identical after a kill,
bad input exit 2. Against analytic numbers: tests/unit/test_stress_path.cpp (the FCC lattice's
C44, no damping)."""
import json
import math
import subprocess

import numpy as np
import pytest

from conftest import GRAINLAB, kill_after_second_checkpoint
from test_lab_tests import CONFIG, VOLATILE, read, sets

CSS = ['test.type="cyclic-simple-shear"', 'test.boundary="periodic"', "sample.e0_tolerance=1.0",
       'test.shear_strain_rate="auto"', "test.axial_strain_rate=\"auto\"", "test.final_axial_strain=0.2"]


def run_css(out, *extra, threads=1):
    proc = subprocess.run([GRAINLAB, "run", CONFIG, "--out", str(out), "--quiet", "--threads", str(threads),
                           *sets(*CSS, *extra)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return read(out)


def last_loop(c, amplitude_index):
    """Records of the measured cycle of an amplitude: from the reversal at +gamma_a that starts it
    (the first record with cycle 0.5) to the one that closes it (the first with cycle 1.0 moving
    back, load_direction -1)."""
    seg = c["amplitude"] == amplitude_index + 1
    idx = np.flatnonzero(seg)
    start = idx[np.flatnonzero(c["cycle"][idx] == 0.5)[0]]
    end = idx[np.flatnonzero((c["cycle"][idx] == 1.0) & (c["load_direction"][idx] == -1))[0]]
    return slice(start - 1, end + 1)  # the records just before each reversal's step too


def test_modulus_and_damping_from_the_loops(tmp_path):
    c, s = run_css(tmp_path / "css", "test.shear_strain_amplitudes=[1e-4, 1e-2]", "test.cycles_per_amplitude=1")
    assert s["test"] == "cyclic-simple-shear" and s["status"] == "completed"
    amps, g, ratio, xi = s["shear_strain_amplitudes"], s["G_secant_MPa"], s["G_over_Gmax"], s["damping_ratio"]
    assert len(amps) == len(g) == len(ratio) == len(xi) == 2
    assert amps == pytest.approx([1e-4, 1e-2], rel=0.02)
    assert ratio[0] == 1.0 and s["Gmax_MPa"] == g[0]
    # A sand: stiffness degrades and damping grows with the amplitude.
    assert ratio[1] < 0.6 and xi[1] > 0.03 and xi[1] > xi[0]
    # Recomputed from the records of the large amplitude's loop.
    loop = last_loop(c, 1)
    gamma = (c["gamma"] - c["gamma"][0])[loop]
    tau = c["tau"][loop]
    g_rec = (tau.max() - tau.min()) / (gamma.max() - gamma.min())
    assert g_rec / 1e6 == pytest.approx(g[1], rel=0.05)
    area = np.trapz(tau, gamma)
    half = 0.5 * (gamma.max() - gamma.min())
    xi_rec = area / (4 * math.pi * 0.5 * g_rec * half ** 2)
    assert xi_rec == pytest.approx(xi[1], rel=0.15)
    # Gmax and the probe's small-strain E0 of the same sample: G = E/(2(1 + nu)) for an isotropic
    # solid, which a sample consolidated isotropically nearly is.
    g_probe = s["E0_MPa"] / (2 * (1 + s["nu0"]))
    assert s["Gmax_MPa"] == pytest.approx(g_probe, rel=0.25)
    assert any("above 1e-5" in w for w in s["warnings"])


def test_undrained_cycles_hold_the_volume(tmp_path):
    c, s = run_css(tmp_path / "u", 'test.drainage="undrained"', "test.shear_strain_amplitudes=[1e-3]",
                   "test.cycles_per_amplitude=2")
    assert s["drainage"] == "undrained" and s["volume_drift_max"] < 1e-6
    assert np.abs(c["eps_v"]).max() < 1e-6
    p0 = s["confining_pressure"]
    assert np.allclose(c["u"], p0 - c["sigma1"], rtol=0, atol=1e-7 * p0)
    assert s["ru_max"] == pytest.approx(max(0.0, (c["u"] / p0).max()), abs=0.05)
    assert len(s["G_secant_MPa"]) == 1
    assert s["liquefied"] is False and s["liquefied_at_amplitude"] is None
    assert s["ru_max_per_amplitude"] == pytest.approx([(c["u"] / p0).max()], rel=1e-8)


def test_a_loose_sample_liquefies_and_says_at_which_amplitude(tmp_path):
    """A loose soft sample (e0 ~ 0.79) cycled undrained: at gamma_a = 1e-3 u builds up a little, at
    1e-2 sigma_zz falls to zero (ru = u/p0 -> 1). ru per amplitude is the records' largest u/p0 of
    that amplitude, `liquefied` and the first amplitude that reached test.ru_limit follow from it,
    and a warning says that G/Gmax there is not a modulus curve."""
    c, s = run_css(tmp_path / "l", 'test.drainage="undrained"', "test.shear_strain_amplitudes=[1e-3, 1e-2]",
                   "test.cycles_per_amplitude=2", "sample.prep_friction_deg=30", "test.probe_strain=0")
    p0, limit = s["confining_pressure"], 0.95  # test.ru_limit's default
    per = [(c["u"][c["amplitude"] == k + 1] / p0).max() for k in range(2)]
    assert s["ru_max_per_amplitude"] == pytest.approx(per, rel=1e-8)  # the CSV's digits
    assert per[0] < limit <= per[1]
    assert s["liquefied"] is True
    assert s["liquefied_at_amplitude"] == pytest.approx(s["shear_strain_amplitudes"][1])
    # ru is u/p0 of sigma_zz: at most 1 but for the constraint's round-off (a few Pa of tension).
    assert limit <= s["ru_max"] <= 1 + 1e-4
    assert s["G_over_Gmax"][1] < 0.3
    assert any("liquefied" in w and "gamma_a = 0.01" in w for w in s["warnings"])


def test_kill_and_resume_is_bit_identical(tmp_path):
    extra = ["test.shear_strain_amplitudes=[1e-4, 1e-3]", "test.cycles_per_amplitude=1", "output.checkpoint_every=1e-4"]
    whole = tmp_path / "whole"
    a = run_css(whole, *extra)
    cut = tmp_path / "cut"
    proc = subprocess.Popen([GRAINLAB, "run", CONFIG, "--out", str(cut), "--quiet", "--threads", "1",
                             *sets(*CSS, *extra)])
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=300)
    resumed = subprocess.run([GRAINLAB, "resume", str(cut), "--quiet"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert (whole / "timeseries.csv").read_text() == (cut / "timeseries.csv").read_text()
    sb = json.loads((cut / "summary.json").read_text())
    assert {k: v for k, v in a[1].items() if k not in VOLATILE} == {k: v for k, v in sb.items() if k not in VOLATILE}


@pytest.mark.parametrize("extra,key,words", [
    (["test.shear_strain_amplitudes=[1e-3, 1e-4]"], "test.shear_strain_amplitudes", ["strictly increasing"]),
    (["test.shear_strain_amplitudes=[0.5]"], "test.shear_strain_amplitudes", ["[1e-7, 0.1]"]),
    (["test.shear_strain_amplitudes=[]"], "test.shear_strain_amplitudes", ["1 to 16"]),
    ([f"test.shear_strain_amplitudes=[{', '.join(str(1e-6 * (k + 1)) for k in range(17))}]"],
     "test.shear_strain_amplitudes", ["1 to 16"]),
    (["test.cycles_per_amplitude=0"], "test.cycles_per_amplitude", ["1"]),
    (['test.boundary="walls"'], "test.type", ['test.boundary = "periodic"']),
])
def test_bad_input_is_refused(extra, key, words):
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets(*CSS, *extra)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and key in line, line
    for w in words:
        assert w in line, f"{w!r} not in {line}"


def test_amplitudes_of_another_test_warn():
    proc = subprocess.run([GRAINLAB, "check", CONFIG, *sets("test.shear_strain_amplitudes=[1e-4]")],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "warning: test.shear_strain_amplitudes = " in proc.stderr and "is ignored" in proc.stderr
