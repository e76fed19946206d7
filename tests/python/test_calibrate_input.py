"""`grainlab calibrate` refuses bad config and target files with exit 2 and one line naming the
key, the value and what is allowed -- before any run starts."""
import json
import os

import pytest

CONFIG = os.path.join(os.path.dirname(__file__), "..", "data", "calibrate-small.toml")

GOOD = """
[[parameter]]
key = "contact.friction_deg"
min = 20.0
max = 40.0
[[target]]
key = "phi_peak_deg"
value = 41.0
"""

CASES = [
    # (what the target file says, words the message must contain)
    ("[paramter]\nkey = 1\n" + GOOD, ["paramter", "unknown section"]),
    (GOOD.replace("min = 20.0", "mn = 20.0"), ["mn", "unknown key", "min"]),
    (GOOD.replace("max = 40.0", "max = 10.0"), ["max", "10", "> min"]),
    (GOOD.replace("max = 40.0", "max = 95.0"), ["contact.friction_deg", "95", "not accepted"]),
    (GOOD.replace("contact.friction_deg", "contact.frictoin_deg"), ["contact.frictoin_deg", "unknown key"]),
    (GOOD.replace("contact.friction_deg", "contact.rolling_friction").replace("20.0", "0.1").replace("40.0", "0.3"),
     ["contact.rolling_friction", "rolling-linear"]),
    (GOOD.replace("contact.friction_deg", "sample.n_particles").replace("20.0", "100.0").replace("40.0", "300.0"),
     ["sample.n_particles", "not a continuous"]),
    (GOOD.replace("contact.friction_deg", "sample.seed"), ["sample.seed", "[evaluation] seeds"]),
    (GOOD.replace("max = 40.0", "max = 40.0\nlog = true").replace("20.0", "0.0"), ["min", "log = true"]),
    (GOOD + GOOD.split("[[target]]")[0], ["contact.friction_deg", "each parameter once"]),
    (GOOD.replace('"phi_peak_deg"', '"phi peak"'), ["target[1].key", "phi peak", "summary.json"]),
    (GOOD.replace("value = 41.0", "value = 0.0"), ["scale", "value = 0"]),
    (GOOD.replace("value = 41.0", "valeu = 41.0"), ["target[1]", "valeu", "unknown key"]),
    (GOOD.split("[[target]]")[0], ["target", "at least one"]),
    (GOOD + '[evaluation]\nseeds = [1, 1]\n', ["evaluation.seeds", "distinct"]),
    (GOOD + '[evaluation]\nseeds = 0\n', ["evaluation.seeds", "0"]),
    (GOOD + '[optimizer]\nalgorithm = "adam"\n', ["optimizer.algorithm", "adam", "bobyqa"]),
    (GOOD + '[optimizer]\nmax_evaluations = 0\n', ["optimizer.max_evaluations", "integer"]),
    (GOOD + '[sensitivity]\nstep = 0.9\n', ["sensitivity.step", "0.9"]),
    (GOOD + '[execution]\nscheduler = "localhost:8786"\n', ["execution.scheduler", "localhost:8786", "tcp://HOST:PORT"]),
    (GOOD + '[curve]\nfile = "missing.csv"\n', ["curve.file", "missing.csv", "regular file"]),
    (GOOD + "[[parameter]\n", ["line", "target"]),
]


@pytest.mark.parametrize("text,words", CASES)
def test_bad_target_is_exit_2_naming_key_and_value(grainlab, tmp_path, text, words):
    target = tmp_path / "target.toml"
    target.write_text(text)
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--out", str(tmp_path / "out"), check=2)
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1, message
    for w in words:
        assert w in message, (w, message)
    assert not (tmp_path / "out" / "runs").exists()


CURVES = [
    ("eps1,q\n0,0\n0.01,100\n0.005,120\n", ["eps1", "increase"]),
    ("eps1,q\n0,0\n0.01,abc\n0.02,120\n", ["column q", "abc", "finite number"]),
    ("eps,q\n0,0\n0.01,100\n0.02,120\n", ["header", "eps1"]),
    ("eps1,q\n0,0\n0.01,100\n", ["at least 3"]),
    ("eps1,q\n0,0\n0.01,100,3\n0.02,120\n", ["line 3", "cells"]),
    ("eps1,sigma1\n0,1\n0.01,2\n0.02,3\n", ["curve.file", "q", "eps_v"]),
]


@pytest.mark.parametrize("csv,words", CURVES)
def test_bad_curve_file_is_exit_2(grainlab, tmp_path, csv, words):
    (tmp_path / "lab.csv").write_text(csv)
    target = tmp_path / "target.toml"
    target.write_text(GOOD + '[curve]\nfile = "lab.csv"\n')
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--out", str(tmp_path / "out"), check=2)
    for w in words:
        assert w in proc.stderr, (w, proc.stderr)


def test_curve_beyond_the_run_and_unknown_quantity(grainlab, tmp_path):
    (tmp_path / "lab.csv").write_text("eps1,q,eps_v\n0,0,0\n2,100,-0.1\n5,120,-0.5\n")
    target = tmp_path / "target.toml"
    target.write_text(GOOD + '[curve]\nfile = "lab.csv"\nstrain_unit = "percent"\neps1_max = 4.0\n')
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--out", str(tmp_path / "o1"), check=2)
    assert "curve.eps1_max" in proc.stderr and "final_axial_strain" in proc.stderr
    target.write_text(GOOD + '[curve]\nfile = "lab.csv"\nquantities = ["q", "tau"]\n')
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--out", str(tmp_path / "o2"), check=2)
    assert "curve.quantities" in proc.stderr and "sigma1_over_sigma3" in proc.stderr


def test_bad_config_and_scheduler_options(grainlab, tmp_path):
    target = tmp_path / "target.toml"
    target.write_text(GOOD)
    proc = grainlab("calibrate", str(tmp_path / "nope.toml"), "--target", str(target), check=2)
    assert "nope.toml" in proc.stderr
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--scheduler", "8786", "--out", str(tmp_path / "o"), check=2)
    assert "--scheduler" in proc.stderr and "tcp://HOST:PORT" in proc.stderr
    proc = grainlab("calibrate", CONFIG, "--target", str(tmp_path / "none.toml"), check=2)
    assert "none.toml" in proc.stderr


def test_folder_of_another_calibration_is_refused(grainlab, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    target = tmp_path / "target.toml"
    target.write_text(GOOD)
    (out / "calibration.json").write_text(json.dumps({"format": "grainlab-calibration-1", "config_resolved": "x",
                                                      "target": {}, "config": "other.toml"}))
    proc = grainlab("calibrate", CONFIG, "--target", str(target), "--out", str(out), check=2)
    assert "another config" in proc.stderr and str(out) in proc.stderr
