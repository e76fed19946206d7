"""Every preset, and the tests and laws no preset runs, shortened and on one thread, give the
timeseries.csv recorded in tests/data/fingerprints.json, byte for byte.

A change detector for behaviour-preserving redesigns (the open engine of issue 25, the boundary
seam of issue 24), not validation: a commit that changes results on purpose regenerates the file
(tests/data/fingerprints.py --write) and names the cases that changed and why."""
import json
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "data"))
import fingerprints  # noqa: E402

from conftest import GRAINLAB  # noqa: E402

RECORDED = json.load(open(fingerprints.FILE))


def test_every_case_is_recorded():
    assert sorted(RECORDED) == sorted(fingerprints.CASES)


def test_every_preset_has_a_case():
    presets = os.path.join(os.path.dirname(__file__), "..", "..", "presets")
    names = {f[:-5] for f in os.listdir(presets) if f.endswith(".toml")}
    used = {config.split(":", 1)[1] for config, _ in fingerprints.CASES.values()}
    assert names <= used, f"presets without a fingerprint case: {sorted(names - used)}"


@pytest.mark.parametrize("name", sorted(fingerprints.CASES))
def test_timeseries_unchanged(name, tmp_path):
    digest = fingerprints.run_case(GRAINLAB, name, str(tmp_path))
    assert digest == RECORDED[name], (
        f"{name}: timeseries.csv changed (sha256 {digest[:16]}, recorded {RECORDED[name][:16]}); if the change "
        f"is intended, regenerate with tests/data/fingerprints.py --write and say why in the commit")
