"""sample.method = "loose-moment-free" (docs/moduli.md): compaction without contact moments, moments
switched on afterwards; the coordination of the prepared sample in summary.json."""
import csv
import json
import os

SMALL = os.path.join(os.path.dirname(__file__), "..", "data", "small-triaxial.toml")


def prepared(grainlab, out, *sets):
    args = ["run", SMALL, "--out", str(out), "--quiet", "--threads", "1", "--set", "test.final_axial_strain=0.001",
            "--set", "test.probe_strain=0"]
    for s in sets:
        args += ["--set", s]
    grainlab(*args, check=0, timeout=600)
    return json.loads((out / "summary.json").read_text())


def test_moment_free_compaction_is_denser_at_the_same_friction(grainlab, tmp_path):
    # Contact moments let grains stand in arches: at the same preparation friction, compaction with
    # moments (the [W] law, eta = 1) ends looser than the same compaction with the moments off. A
    # method that left the moments on would give the same e0.
    common = ["sample.prep_friction_deg=60"]
    with_moments = prepared(grainlab, tmp_path / "m", *common, 'sample.method="compaction"')
    free = prepared(grainlab, tmp_path / "f", *common, 'sample.method="loose-moment-free"')
    assert free["preparation_method"] == "loose-moment-free"
    assert free["e0"] < with_moments["e0"] - 0.01
    for s in (with_moments, free):
        # Z is that of the prepared sample: the first record of shearing sees the same contacts.
        with open(tmp_path / ("m" if s is with_moments else "f") / "timeseries.csv", newline="") as f:
            first = next(csv.DictReader(f))
        assert abs(float(first["Z"]) - s["Z"]) < 1e-9
        assert s["Z_mech"] >= s["Z"] and 0.0 <= s["rattler_fraction"] < 1.0
        assert s["house_of_cards"] == (s["Z"] < 2.0)
    # Without moments the grains cannot stand at Z < 2 in mechanical equilibrium of the non-rattlers.
    assert free["Z_mech"] > 2.0


def test_moment_free_is_for_spheres(grainlab):
    proc = grainlab("check", SMALL, "--set", 'sample.method="loose-moment-free"', "--set", 'sample.shape={type="ellipsoid", elongation=0.7}',
                    check=2)
    assert "sample.method" in proc.stderr and "loose-moment-free" in proc.stderr
