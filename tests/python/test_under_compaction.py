"""sample.method = "under-compaction" (issue 27 §2, Ladd's moist tamping analogue) end to end through
the CLI: deterministic for a seed and thread count; the platen's targets follow Ladd's heights (the
last layer ends the stack at e0: the cube's side); each layer's tamping reported with whether the
tamper reached its height (it stops at the confining pressure); thin layers warned about; bad input
exits 2 naming the key. The solid volume of a slice (the void ratio profile) and the slab placement
against hand numbers: tests/unit/test_layers.cpp."""
import pytest

from test_gravity import run as run_cli

TAMP = ["sample.n_particles=150", 'sample.grading={type="uniform", d_min=4e-3, d_max=6e-3}',
        'sample.method="under-compaction"', "sample.layers=2", "sample.e0=0.75", 'test.type="isotropic"',
        "sample.prep_friction_deg=10", "output.plots=false", "output.vtk_every_strain=0", "output.save_packing=true",
        "test.probe_strain=0"]  # the probe stalls on this loose sample (test_gravity.DEPOSIT)


def run(out, *extra, base=TAMP, check=0):
    # test_gravity's runner (grainlab run on the small-triaxial config, one thread) with the tamping's keys.
    return run_cli(out, *extra, base=base, check=check)


def test_under_compaction_is_deterministic_and_reported(tmp_path):
    (c, s), proc = run(tmp_path / "a", "sample.under_compaction=0.2")
    (_, s2), _ = run(tmp_path / "b", "sample.under_compaction=0.2")
    assert (tmp_path / "a" / "timeseries.csv").read_bytes() == (tmp_path / "b" / "timeseries.csv").read_bytes()
    assert (tmp_path / "a" / "packing.txt").read_bytes() == (tmp_path / "b" / "packing.txt").read_bytes()
    assert s["preparation_method"] == "under-compaction" and s["e0_searched"] is False
    u = s["under_compaction"]
    assert u["layers"] == 2 and u["under_compaction"] == 0.2 and u["target_void_ratio"] == 0.75
    for key in ("target_heights", "tamped_void_ratio", "tamper_stress", "tamper_reached"):
        assert len(u[key]) == 2, key
    # Ladd's heights: the last layer ends the stack at e0, i.e. at the side of the footprint (a cube
    # at e0); the first, under-compacted by U = 0.2, stands above half of it.
    h = u["target_heights"]
    assert h[1] == pytest.approx(u["width"], rel=1e-9)
    assert h[1] / 2 < h[0] < h[1]
    # The tamper stops at its height or at the confining pressure p (100 kPa), never above it by more
    # than one step's increment.
    for stress, reached in zip(u["tamper_stress"], u["tamper_reached"]):
        assert stress > 0 and (reached or stress < 1.1 * 100e3), (stress, reached)
    assert len(u["void_ratio_profile"]) == 2 and len(u["prepared_void_ratio_profile"]) == 2
    assert all(v is None or v > 0.3 for v in u["prepared_void_ratio_profile"])
    assert u["Z"] > 0 and u["gravity_work"] > 0 and u["steps"] > 0
    # 150 spheres in two layers: each about 2.6 d50 thick, mostly wall, and said so.
    assert u["layer_thickness_d50"] < 3
    assert any("sample.layers = 2" in w for w in s["warnings"]), s["warnings"]
    assert "W_gravity" in c
    resolved = (tmp_path / "a" / "config.resolved.toml").read_text()
    assert "layers = 2" in resolved and "under_compaction = 0.2" in resolved


@pytest.mark.parametrize("extra,key", [
    (["sample.layers=1"], "sample.layers"),
    (["sample.layers=51"], "sample.layers"),
    (["sample.layers=2.5"], "sample.layers"),
    (["sample.under_compaction=0.5"], "sample.under_compaction"),
    (["sample.under_compaction=-0.1"], "sample.under_compaction"),
    (['sample.method="compaction"', "sample.layers=3"], "sample.layers"),
    (['sample.method="growth"', "sample.under_compaction=0.1"], "sample.under_compaction"),
    (['test.boundary="periodic"'], "sample.gravity"),
    (['sample.shape={type="ellipsoid", elongation=0.7}'], "sample.method"),
    (["sample.gravity=[0, -9.81, 0]"], "sample.gravity"),
    (["sample.n_particles=2"], "sample.layers"),           # empty layers (placement had nothing to place)
    (["sample.n_particles=30", "sample.layers=5"], "sample.layers"),
])
def test_bad_under_compaction_input_exits_2_naming_the_key(tmp_path, extra, key):
    base = TAMP
    if any(x.startswith("sample.method=") for x in extra):  # another method: without the tamping's keys
        base = [x for x in TAMP if x.split("=")[0] not in ("sample.method", "sample.layers", "sample.e0",
                                                            "sample.prep_friction_deg")]
    _, proc = run(tmp_path / "bad", *extra, base=base, check=2)
    assert key in proc.stderr and any(w in proc.stderr for w in ("allowed", "must", "only used")), proc.stderr
    assert not (tmp_path / "bad" / "summary.json").exists()
