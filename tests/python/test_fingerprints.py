"""Every preset, and the tests and laws no preset runs, shortened and on one thread, give the
timeseries.csv recorded in tests/data/fingerprints.json, byte for byte.

A change detector for behaviour-preserving redesigns (the open engine of issue 25, the boundary
seam of issue 24), not validation: a commit that changes results on purpose regenerates the file
(tests/data/fingerprints.py --write) and names the cases that changed and why."""
import json
import os
import re
import subprocess
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


def simd_targets():
    """The GRAINLAB_SIMD names this program and CPU allow, read from the refusal of a bad one."""
    proc = subprocess.run([GRAINLAB, "presets"], capture_output=True, text=True,
                          env={**os.environ, "GRAINLAB_SIMD": "no-such-target"})
    assert proc.returncode == 2, proc.stderr
    m = re.search(r"allowed: (.*)$", proc.stderr.strip())
    assert m, proc.stderr
    return [t.strip() for t in m.group(1).split(",")]


# Issue 25 part 2: the whole run is bit-identical whatever vector target the kernels use. One case
# on walls and one in a periodic cell (the flow map), each on every target of this CPU.
@pytest.mark.parametrize("name", ["quick-triaxial", "periodic-triaxial"])
def test_every_simd_target_gives_the_same_run(name, tmp_path):
    targets = simd_targets()
    assert "scalar" in targets and len(targets) >= 3, targets
    # "best" is one of the others, and the unit test covers ssse3 (tests/unit/test_integrate_simd.cpp).
    for target in [t for t in targets if t not in ("best", "ssse3")]:
        digest = fingerprints.run_case(GRAINLAB, name, str(tmp_path), simd=target)
        assert digest == RECORDED[name], f"{name} with GRAINLAB_SIMD={target}: timeseries.csv differs"
