"""ParaView snapshots read back with a real reader (meshio): counts and values match the run."""
import csv
import json
import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np


def test_vtk_snapshots_read_back(grainlab, data_dir, tmp_path):
    out = tmp_path / "run"
    grainlab("run", os.path.join(data_dir, "small-triaxial.toml"), "--out", str(out), "--quiet",
             "--set", "sample.n_particles=100", "--set", "test.final_axial_strain=0.02",
             "--set", "output.vtk_every_strain=0.01", check=0)
    vtk = out / "vtk"
    # A time index per kind: snapshots at eps1 = 0, 0.01, 0.02.
    for kind in ("particles", "contacts", "walls"):
        sets = ET.parse(vtk / f"{kind}.pvd").getroot().findall("./Collection/DataSet")
        assert [round(float(s.get("timestep")), 3) for s in sets] == [0.0, 0.01, 0.02]
        for s in sets:
            assert (vtk / s.get("file")).exists()

    with open(out / "timeseries.csv") as f:
        last = list(csv.DictReader(f))[-1]
    summary = json.loads((out / "summary.json").read_text())

    particles = meshio.read(vtk / "particles_0002.vtu")
    assert particles.points.shape == (100, 3)
    radius = particles.point_data["radius"].ravel()
    assert radius.min() >= 2.0e-3 - 1e-12 and radius.max() <= 3.0e-3 + 1e-12
    assert particles.point_data["velocity"].shape == (100, 3)
    # The angle of the composed rotation cannot exceed the path integral of |w| dt, nor 180 deg.
    angle = particles.point_data["rotation_deg"].ravel()
    path = particles.point_data["rotation_path_deg"].ravel()
    assert np.all(angle <= path + 1e-6) and angle.max() <= 180.0
    assert path.max() > 0.0

    contacts = meshio.read(vtk / "contacts_0002.vtu")
    lines = contacts.cells_dict["line"]
    # Z = 2 Nc / N at the same instant as the last record.
    assert len(lines) == round(float(last["Z"]) * 100 / 2)
    fn = contacts.cell_data["normal_force"][0].ravel()
    assert np.all(fn > 0.0)
    # Contact count per particle: pair contacts from the network, plus wall contacts.
    counts = particles.point_data["contacts"].ravel()
    per_particle = np.bincount(lines.ravel(), minlength=100)
    assert np.all(counts >= per_particle)

    walls = meshio.read(vtk / "walls_0002.vtu")
    assert len(walls.cells_dict["quad"]) == 6
    stress = walls.cell_data["normal_stress"][0].ravel()
    # Walls in order x-, x+, y-, y+, z-, z+. The snapshot holds the walls' stresses at its step, the
    # time series their mean over the last recording interval: the platens agree with sigma1 of the
    # last record to the step-to-step noise, the lateral walls with the servo target.
    assert abs(0.5 * (stress[4] + stress[5]) / float(last["sigma1"]) - 1.0) < 0.15
    assert abs(0.5 * (stress[0] + stress[1]) / float(last["sigma2"]) - 1.0) < 0.05
    assert stress[4] > 1.5 * stress[0]
    assert summary["status"] == "completed"


def test_band_slice_plot(grainlab, data_dir, tmp_path):
    """plots/band_slice.png: a slice of the last snapshot's local shear strain, with the band's trace or
    the statement that none was found (the summary's shear_band)."""
    out = tmp_path / "run"
    grainlab("run", os.path.join(data_dir, "small-triaxial.toml"), "--out", str(out), "--quiet",
             "--set", "sample.n_particles=100", "--set", "test.final_axial_strain=0.01",
             "--set", "output.band_strain_window=0.0025",
             "--set", "output.vtk_every_strain=0.01", "--set", "output.plots=true", check=0)
    summary = json.loads((out / "summary.json").read_text())
    band = summary["shear_band"]
    # Four windows of 0.25 % closed: the band was looked for, so detected is a bool, and every value
    # but detected is null exactly when no band was found.
    assert isinstance(band["detected"], bool)
    for key, value in band.items():
        if key not in ("detected", "onset_eps1", "onset_over_peak", "void_ratio_inside", "void_ratio_outside"):
            assert (value is None) == (not band["detected"]), key
    assert (out / "plots" / "band_slice.png").stat().st_size > 1000
    with open(out / "timeseries.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    closed = [float(r["eps1"]) for r in rows if r["band_measured"] == "1"]
    # One window closes at the first record past each 0.25 % of axial strain since the last one, and
    # a last one at the end of the test (at least half a window).
    assert 4 <= len(closed) <= 5, closed
    assert closed[-1] == float(rows[-1]["eps1"])
    starts = [0.0] + closed[:-1]
    for start, end in zip(starts[:-1], closed[:-1]):
        assert 0.0025 * (1 - 1e-6) <= end - start < 0.0025 + 0.0002, (start, end)
    assert 0.00125 * (1 - 1e-6) <= closed[-1] - starts[-1] < 0.0025 + 0.0002
    # Between the window ends the band was not looked for: its columns are empty.
    for r in rows:
        if r["band_measured"] == "0":
            assert r["band_inclination_deg"] == "" and r["band_thickness_d50"] == ""
    # The increment field of the last window is in the snapshots, beside the cumulative one.
    last = sorted((out / "vtk").glob("particles_*.vtu"))[-1]
    m = meshio.read(last)
    for field in ("strain_increment", "in_band_increment", "local_shear_strain", "in_band"):
        assert field in m.point_data, field
    inc = m.point_data["strain_increment"].ravel()
    assert np.all(np.isfinite(inc)) and inc.max() > 0
