"""`grainlab analyse DIR` on small synthetic run folders: it writes every output, its numbers agree
with an independent computation here (numpy), nulls stay nulls, and bad input exits 2 with one
line naming the file (and line) at fault."""
import csv
import json
import math
import os
import shutil

import numpy as np
import pytest

INDEX_HEADER = "index,step,eps1,volume,sxx,syy,szz,sxy,sxz,syz"
PARTICLES_HEADER = "id,shape,x,y,z,a,b,c,ux,uy,uz,frictionless"
CONTACTS_HEADER = "a,b,nx,ny,nz,fx,fy,fz,ax,ay,az,bx,by,bz"
R = 1e-3  # sphere radius [m]
VOLUME = 1e-4


def axi(a):
    return np.diag([-a / 3, -a / 3, 2 * a / 3])


def random_network(rng, n_particles, n_contacts, ar, an, f0=10.0):
    """Contacts between random pairs with normals from (1 + ar:nn)/4pi and normal forces
    f0 (1 + an:nn) X, X ~ Gamma(2, 1/2); equal spheres, so branch vectors are +-R n."""
    normals = []
    while len(normals) < n_contacts:
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        if rng.uniform() * 2.0 < 1.0 + n @ ar @ n:
            normals.append(n)
    normals = np.array(normals)
    fn = f0 * (1.0 + np.einsum("ki,ij,kj->k", normals, an, normals)) * rng.gamma(2.0, 0.5, n_contacts)
    a = rng.integers(0, n_particles, n_contacts)
    b = (a + 1 + rng.integers(0, n_particles - 1, n_contacts)) % n_particles
    return a, b, normals, fn


def write_snapshot(micro, index, particles, contacts):
    with open(os.path.join(micro, "particles_%04d.csv" % index), "w") as f:
        f.write(PARTICLES_HEADER + "\n")
        for pid in particles:
            f.write("%d,sphere,0,0,0,%r,,,,,,0\n" % (pid, R))
    with open(os.path.join(micro, "contacts_%04d.csv" % index), "w") as f:
        f.write(CONTACTS_HEADER + "\n")
        for a, b, n, force in contacts:
            branch_a = R * n
            if isinstance(b, str):  # wall
                f.write("%d,%s,%r,%r,%r,%r,%r,%r,%r,%r,%r,,,\n" % (a, b, *n, *force, *branch_a))
            else:
                f.write("%d,%d,%r,%r,%r,%r,%r,%r,%r,%r,%r,%r,%r,%r\n" % (a, b, *n, *force, *branch_a, *(-branch_a)))


def love_weber(contacts):
    s = np.zeros((3, 3))
    for _, b, n, force in contacts:
        branch = R * n if isinstance(b, str) else 2 * R * n
        s += np.outer(force, branch)
    return s / VOLUME


def q_over_p(s):
    p = np.trace(s) / 3
    return (s[2, 2] - 0.5 * (s[0, 0] + s[1, 1])) / p


@pytest.fixture
def run_dir(tmp_path):
    """Three snapshots: an isotropic network (start), an anisotropic one (the peak of q/p) and a
    cubic lattice whose normals hold only six directions (no force anisotropy can be fitted)."""
    rng = np.random.default_rng(7)
    micro = tmp_path / "micro"
    micro.mkdir()
    expected = []
    index_rows = []
    for k, (ar, an, qp) in enumerate([(axi(0.0), axi(0.0), 0.0), (axi(0.45), axi(0.6), 0.8)]):
        a, b, normals, fn = random_network(rng, 400, 2500, ar, an)
        contacts = [(int(i), int(j), n, f * n) for i, j, n, f in zip(a, b, normals, fn)]
        # Particle 400 touches only a wall: a rattler; 401 touches nothing.
        contacts.append((400, "w3", np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 5.0])))
        write_snapshot(str(micro), k, range(402), contacts)
        p = 1e5
        stress = np.diag([p * (1 - qp / 3)] * 2 + [p * (1 + 2 * qp / 3)])
        index_rows.append("%d,%d,%r,%r,%r,%r,%r,0,0,0" % (k, 1000 * (k + 1), 0.01 * k, VOLUME, *np.diag(stress)))
        expected.append({"contacts": contacts, "normals": normals, "stress": stress, "particles": 402})
    # The lattice: 3x3x3 simple cubic, forces 2 N axially and 1 N laterally, plus one rattler.
    pos = {(i, j, k): 9 * i + 3 * j + k for i in range(3) for j in range(3) for k in range(3)}
    contacts = []
    for (i, j, k), pid in pos.items():
        for axis, step in ((0, (1, 0, 0)), (1, (0, 1, 0)), (2, (0, 0, 1))):
            other = (i + step[0], j + step[1], k + step[2])
            if other in pos:
                n = np.array(step, dtype=float)
                contacts.append((pid, pos[other], n, (2.0 if axis == 2 else 1.0) * n))
    write_snapshot(str(micro), 2, range(28), contacts)
    index_rows.append("2,3000,0.02,%r,1e5,1e5,1.5e5,0,0,0" % VOLUME)
    expected.append({"contacts": contacts, "normals": np.array([c[2] for c in contacts]), "particles": 28})
    with open(micro / "snapshots.csv", "w") as f:
        f.write(INDEX_HEADER + "\n" + "\n".join(index_rows) + "\n")
    return tmp_path, expected


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_analyse_writes_outputs_that_agree_with_numpy(grainlab, run_dir):
    folder, expected = run_dir
    proc = grainlab("analyse", str(folder), check=0, timeout=300)
    assert "a_r" in proc.stdout
    micro = folder / "micro"
    for name in ["analysis.csv", "analysis.json", "classes.pvd"] + \
            ["classes_%04d.%s" % (k, ext) for k in range(3) for ext in ("csv", "vtu")]:
        assert (micro / name).is_file(), name
    for name in ("rose_start.png", "rose_peak.png", "rose_end.png", "micro_anisotropy.png"):
        assert (folder / "plots" / name).stat().st_size > 10000, name

    rows = read_rows(micro / "analysis.csv")
    summary = json.loads((micro / "analysis.json").read_text())
    assert (summary["start"], summary["peak"], summary["end"]) == (0, 1, 2)
    assert summary["classes"] == 384
    for row, snap, exp in zip(rows, summary["snapshots"], expected):
        contacts = exp["contacts"]
        pp = [c for c in contacts if not isinstance(c[1], str)]
        n = exp["normals"]
        # Coordination: Z over particle-particle contacts; the wall-only particle and the free one
        # are rattlers (fewer than 2 contacts), and the lattice has none (corners have 3).
        assert float(row["Z"]) == pytest.approx(2 * len(pp) / exp["particles"], rel=1e-9)
        assert int(row["contacts"]) == len(pp)
        assert int(row["wall_contacts"]) == len(contacts) - len(pp)
        degree = np.bincount([c[0] for c in pp] + [c[1] for c in pp], minlength=exp["particles"])
        assert snap["contact_histogram"] == np.bincount(degree).tolist()
        # Fabric: a^r = 15/2 dev(<nn>); magnitude sqrt(3/2 a:a) signed by a:s.
        fabric = np.einsum("ki,kj->ij", n, n) / len(n)
        ar = 7.5 * (fabric - np.trace(fabric) / 3 * np.eye(3))
        assert np.allclose(snap["a_r"]["tensor"], ar, atol=1e-12)
        assert float(row["a_r"]) == pytest.approx(math.sqrt(1.5 * np.sum(ar * ar)), rel=1e-6, abs=1e-9)
        # Love-Weber stress of all contacts (walls with their half branch).
        assert np.allclose(snap["stress_contacts"], love_weber(contacts), rtol=1e-9, atol=1e-6)
        if "stress" in exp:
            assert float(row["q_over_p"]) == pytest.approx(q_over_p(exp["stress"]), rel=1e-9, abs=1e-12)
    # Rattlers of the random networks: particles without 2 contacts, walls counted.
    for row, exp in zip(rows[:2], expected[:2]):
        count = np.zeros(exp["particles"], dtype=int)
        for c in exp["contacts"]:
            count[c[0]] += 1
            if not isinstance(c[1], str):
                count[c[1]] += 1
        assert int(row["rattlers"]) >= int(np.sum(count < 2))
    assert float(rows[2]["rattler_fraction"]) == pytest.approx(1 / 28)
    # Force anisotropy of the anisotropic network near its true a_n = 0.6 (sampling error ~0.05
    # for 2500 contacts; the unit tests check this rigorously), the isotropic one near 0.
    assert float(rows[1]["a_n"]) == pytest.approx(0.6, abs=0.2)
    assert abs(float(rows[0]["a_n"])) < 0.2
    assert float(rows[1]["q_over_p_sff"]) > 0.3
    # The lattice has normals in six directions only: the force expansion cannot be fitted, and
    # the table says so with empty fields (null), not zeros.
    assert rows[2]["a_n"] == "" and rows[2]["q_over_p_sff"] == ""
    assert summary["snapshots"][2]["a_n"] is None and summary["snapshots"][2]["f0"] is None
    # Class averages: 384 classes, areas sum to 4 pi, every contact counted for n and -n.
    classes = read_rows(micro / "classes_0001.csv")
    assert len(classes) == 384
    assert sum(float(c["area"]) for c in classes) == pytest.approx(4 * math.pi, rel=1e-9)  # 10 digits
    assert sum(int(c["count"]) for c in classes) == 2 * (len(expected[1]["contacts"]) - 1)


def test_class_grid_opens_in_meshio(grainlab, run_dir):
    meshio = pytest.importorskip("meshio")
    folder, expected = run_dir
    grainlab("analyse", str(folder), "--no-plots", "--quiet", "--classes", "2", check=0)
    mesh = meshio.read(str(folder / "micro" / "classes_0001.vtu"))
    assert sum(len(block.data) for block in mesh.cells) == 96
    counts = mesh.cell_data["count"][0]
    assert counts.sum() == 2 * (len(expected[1]["contacts"]) - 1)
    radii = np.linalg.norm(mesh.points, axis=1)
    assert np.allclose(radii, 1.0)
    assert not (folder / "plots").exists()


def test_bad_input_exits_2_naming_what(grainlab, run_dir, tmp_path):
    folder, _ = run_dir
    proc = grainlab("analyse", str(tmp_path / "nowhere"), check=2)
    assert "nowhere" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    empty = tmp_path / "empty"
    empty.mkdir()
    proc = grainlab("analyse", str(empty), check=2)
    assert "snapshots.csv" in proc.stderr and "does not exist" in proc.stderr
    proc = grainlab("analyse", str(folder), "--classes", "0", check=2)
    assert "--classes" in proc.stderr
    bad = tmp_path / "bad"
    shutil.copytree(folder, bad)
    path = bad / "micro" / "contacts_0001.csv"
    lines = path.read_text().splitlines()
    fields = lines[5].split(",")
    fields[6] = "abc"  # fy
    lines[5] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    proc = grainlab("analyse", str(bad), "--no-plots", check=2)
    assert "contacts_0001.csv: line 6: fy = 'abc': must be a finite number" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
