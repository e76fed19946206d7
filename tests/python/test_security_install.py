"""An installed grainlab (cmake --install) runs from any folder and draws its plots; so does a build
tree moved elsewhere. Nothing is read from the source tree at run time."""
import json
import os
import shutil
import subprocess

from conftest import GRAINLAB

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.path.dirname(os.path.abspath(GRAINLAB))
# A short run of the shipped quick-triaxial preset (compiled into the executable), with plots.
TINY = ["--set", "sample.n_particles=100", "--set", "sample.e0=0.8", "--set", "test.final_axial_strain=0.002",
        "--set", "output.vtk_every_strain=0", "--set", "output.plots=true", "--threads", "1", "--quiet"]


def assert_results_with_plots(folder):
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "completed"
    plots = sorted(os.listdir(folder / "plots"))
    assert {"q_eps1.png", "epsv_eps1.png", "phi_eps1.png"} <= set(plots), plots


def test_installed_program_runs_from_an_empty_folder(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], check=True, capture_output=True)
    exe = prefix / "bin" / "grainlab"
    assert (prefix / "share" / "grainlab" / "tools" / "plot_run.py").is_file()
    assert (prefix / "share" / "grainlab" / "presets" / "data" / "sphericity-synthetic.csv").is_file()
    assert SOURCE.encode() not in exe.read_bytes(), "the executable names its source tree"
    empty = tmp_path / "empty"
    empty.mkdir()
    proc = subprocess.run([str(exe), "run", "preset:quick-triaxial", "--out", "results", *TINY], cwd=empty,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "warning: plot" not in proc.stderr, proc.stderr
    assert_results_with_plots(empty / "results")
    # A preset's data file is found in the installed share folder.
    proc = subprocess.run([str(exe), "check", "preset:rorato-sphericity"], cwd=empty, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert str(prefix / "share" / "grainlab" / "presets" / "data" / "sphericity-synthetic.csv") in proc.stdout


def test_moved_build_tree_still_plots(tmp_path):
    moved = tmp_path / "moved build"
    moved.mkdir()
    shutil.copy2(GRAINLAB, moved / "grainlab")
    shutil.copytree(os.path.join(BUILD, "share"), moved / "share")
    proc = subprocess.run([str(moved / "grainlab"), "run", "preset:quick-triaxial", "--out", "r", *TINY],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert_results_with_plots(tmp_path / "r")


def test_missing_plot_script_is_a_warning_not_a_failure(tmp_path):
    alone = tmp_path / "alone"
    alone.mkdir()
    shutil.copy2(GRAINLAB, alone / "grainlab")
    proc = subprocess.run([str(alone / "grainlab"), "run", "preset:quick-triaxial", "--out", "r", *TINY],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "plot_run.py not found" in proc.stderr
    assert json.loads((tmp_path / "r" / "summary.json").read_text())["status"] == "completed"
    assert not (tmp_path / "r" / "plots").exists()
