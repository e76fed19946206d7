"""Checkpoint and resume: a run killed with SIGKILL during shearing and resumed from its last
checkpoint ends with the same numbers, bit for bit, as the same run left alone."""
import json
import os
import subprocess

from conftest import GRAINLAB, kill_after_second_checkpoint

SETS = ["--set", "sample.n_particles=150", "--set", "test.final_axial_strain=0.03",
        "--set", "output.checkpoint_every=0.004", "--set", "output.vtk_every_strain=0.01",
        "--set", "output.band_strain_window=0.003",  # windows close before the kill, and after it
        "--set", "output.plots=false", "--threads", "2", "--quiet"]
VOLATILE = {"wall_seconds", "particle_steps_per_s", "threads_used", "run_id"}


def outputs(out):
    summary = json.loads((out / "summary.json").read_text())
    # The micromechanics snapshots (network, index) and their analysis too: a resumed run numbers
    # its snapshots on from the checkpoint, as the uninterrupted run did.
    micro = {p.name: p.read_bytes() for p in sorted((out / "micro").iterdir())}
    # The last particle snapshot too: its strain increment is measured from the band windows'
    # start states, which the checkpoint carries.
    last_vtu = sorted((out / "vtk").glob("particles_*.vtu"))[-1].read_bytes()
    return ({k: v for k, v in summary.items() if k not in VOLATILE}, (out / "timeseries.csv").read_text(),
            (out / "vtk" / "particles.pvd").read_text(), micro, last_vtu)


def test_kill_and_resume_is_bit_identical(grainlab, data_dir, tmp_path):
    config = os.path.join(data_dir, "small-triaxial.toml")
    whole = tmp_path / "whole"
    grainlab("run", config, "--out", str(whole), *SETS, check=0)

    cut = tmp_path / "cut"
    proc = subprocess.Popen([GRAINLAB, "run", config, "--out", str(cut), *SETS])
    # A checkpoint beyond the first (written when shearing starts), then kill -9.
    kill_after_second_checkpoint(proc, cut / "checkpoint" / "state.bin", timeout=300)
    assert not (cut / "summary.json").exists()
    assert not (cut / "timeseries.csv").exists()

    proc = grainlab("resume", str(cut), "--quiet", check=0)
    a, b = outputs(whole), outputs(cut)
    assert a[0] == b[0]
    assert a[1] == b[1]
    assert a[2] == b[2]
    assert "snapshots.csv" in a[3] and "analysis.json" in a[3] and "contacts_0003.csv" in a[3]
    assert a[3] == b[3]
    assert b"strain_increment" in a[4] and a[4] == b[4]
    # Resuming a finished run does nothing.
    assert "already completed" in grainlab("resume", str(cut), check=0).stdout


def test_resume_without_checkpoint_is_a_clear_error(grainlab, tmp_path):
    proc = grainlab("resume", str(tmp_path), check=2)
    assert "config.resolved.toml" in proc.stderr
