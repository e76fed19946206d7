"""Shared fixtures for the command-line tests: the grainlab executable and a scratch folder."""
import os
import subprocess

import pytest

GRAINLAB = os.environ.get("GRAINLAB_BIN", os.path.join(os.path.dirname(__file__), "..", "..", "build", "grainlab"))
DATA = os.path.join(os.path.dirname(__file__), "..", "data")

# A 100-sphere triaxial test to 0.3 % axial strain on one thread (about a second): the base of the
# hostile-input tests and the fuzzer, which change one thing at a time.
TINY_CONFIG = """\
[sample]
n_particles = 100
grading = { type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }
e0 = 0.7
seed = 3
prep_friction_deg = 0.0

[test]
type = "triaxial"
confining_pressure = 100.0e3
axial_strain_rate = 1.0
final_axial_strain = 0.003

[solver]
threads = 1

[output]
record_every_strain = 0.0005
vtk_every_strain = 0
checkpoint_every = 0.001
plots = false
"""


@pytest.fixture
def grainlab():
    def run(*args, check=None, timeout=600):
        proc = subprocess.run([GRAINLAB, *args], capture_output=True, text=True, timeout=timeout)
        if check is not None:
            assert proc.returncode == check, f"exit {proc.returncode}\nstdout:\n{proc.stdout}\nstderr:\n{proc.stderr}"
        return proc
    return run


@pytest.fixture
def data_dir():
    return DATA


def kill_after_second_checkpoint(proc, state, timeout=120):
    """Waits until the run `proc` has rewritten its checkpoint `state` once (a checkpoint beyond the
    first, written when shearing starts), then kills it with SIGKILL. Fails if the run ended first."""
    import signal
    import time
    first = None
    deadline = time.time() + timeout
    try:
        while time.time() < deadline and proc.poll() is None:
            if state.exists():
                m = state.stat().st_mtime_ns
                if first is None:
                    first = m
                elif m != first:
                    break
            time.sleep(0.01)
        assert proc.poll() is None, "the run ended before it could be interrupted"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
