"""Shared fixtures for the command-line tests: the grainlab executable and a scratch folder."""
import os
import subprocess

import pytest

GRAINLAB = os.environ.get("GRAINLAB_BIN", os.path.join(os.path.dirname(__file__), "..", "..", "build", "grainlab"))
DATA = os.path.join(os.path.dirname(__file__), "..", "data")


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
