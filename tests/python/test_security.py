"""Safe to run a colleague's config (docs/security.md): folder names reach no shell, results are
never half old and half new, file-system errors name the path, checkpoints and packing files prove
their integrity, and input is bounded. Small runs (100 spheres, --threads 1)."""
import hashlib
import json
import os
import random
import shutil
import signal
import stat
import subprocess
import tempfile
import time

import pytest

from conftest import GRAINLAB, TINY_CONFIG as TINY, kill_after_second_checkpoint



def run(args, cwd=None, timeout=300, **kw):
    """grainlab with an argument vector; bytes arguments pass through unchanged."""
    return subprocess.run([GRAINLAB, *args], cwd=cwd, capture_output=True, timeout=timeout, **kw)


def err(proc):
    return proc.stderr.decode("utf-8", "replace")


def one_line(proc):
    lines = err(proc).strip().splitlines()
    assert len(lines) == 1, err(proc)
    return lines[0]


def tree(path):
    """{relative path: sha256} of every file below path (bytes names)."""
    out = {}
    for root, _, files in os.walk(os.fsencode(path)):
        for f in files:
            p = os.path.join(root, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, os.fsencode(path))] = hashlib.sha256(fh.read()).hexdigest()
    return out


def write(path, text):
    path.write_text(text)
    return str(path)


# --- no shell: any folder name lands literally ---------------------------------------------------

SHELLY = "p$(touch PWNED1) `touch PWNED2`; touch PWNED3 'q\" && echo"


def check_no_stray_files(where):
    for root, dirs, files in os.walk(where):
        for name in dirs + files:
            assert "PWNED" not in name or "p$(touch" in name, os.path.join(root, name)
    for name in os.listdir(tempfile.gettempdir()):
        assert not name.startswith("PWNED"), name


@pytest.mark.parametrize("name", [
    SHELLY.encode(),
    b"new\nline and  spaces \"quoted\" 'single'",
    b"invalid utf8 \xff\xfe\xc3(",
], ids=["shell-metacharacters", "newline-spaces-quotes", "invalid-utf8"])
def test_out_is_taken_literally(tmp_path, name):
    """--out with $(...), backticks, ';', quotes, a newline, spaces or invalid UTF-8: the results and
    plots land in exactly that folder and nothing else appears anywhere."""
    cfg = write(tmp_path / "c.toml", TINY.replace("plots = false", "plots = true"))
    proc = run(["run", cfg, "--out", name, "--quiet"], cwd=tmp_path)
    assert proc.returncode == 0, err(proc)
    assert sorted(os.listdir(os.fsencode(tmp_path))) == sorted([b"c.toml", name])
    folder = os.path.join(os.fsencode(tmp_path), name)
    assert json.load(open(os.path.join(folder, b"summary.json")))["status"] == "completed"
    plots = os.listdir(os.path.join(folder, b"plots"))
    assert b"q_eps1.png" in plots and b"epsv_eps1.png" in plots
    check_no_stray_files(tmp_path)


@pytest.mark.parametrize("dir_value,name", [
    ('"' + SHELLY.replace("\\", "\\\\").replace('"', '\\"') + '"', SHELLY.encode()),
    ('"tab\\there\\nnewline \\u00e9"', "tab\there\nnewline \u00e9".encode()),
], ids=["shell-metacharacters", "escapes"])
def test_output_dir_from_a_config_is_taken_literally(tmp_path, dir_value, name):
    """output.dir written in a config someone sent: same guarantee as --out."""
    cfg = write(tmp_path / "c.toml", TINY.replace("plots = false", f"plots = true\ndir = {dir_value}"))
    proc = run(["run", cfg, "--quiet"], cwd=tmp_path)
    assert proc.returncode == 0, err(proc)
    folder = os.path.join(os.fsencode(tmp_path), name)
    assert os.path.exists(os.path.join(folder, b"plots", b"q_eps1.png"))
    check_no_stray_files(tmp_path)


# --- atomic results -------------------------------------------------------------------------------

def wait_for(path, proc, timeout=120):
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        if os.path.exists(path):
            return True
        time.sleep(0.02)
    return False


def test_killed_rerun_leaves_earlier_results_untouched_and_resumes(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    out = tmp_path / "out"
    assert run(["run", cfg, "--out", str(out), "--quiet"]).returncode == 0
    before = tree(out)
    staging = tmp_path / ".out.grainlab-new"
    # A longer re-run, killed once its first shear checkpoint exists.
    proc = subprocess.Popen([GRAINLAB, "run", cfg, "--out", str(out), "--quiet", "--set", "test.final_axial_strain=0.01"])
    try:
        assert wait_for(staging / "checkpoint" / "state.bin", proc), "the re-run finished before it could be killed"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert tree(out) == before
    # resume continues the killed re-run and only then replaces the earlier results.
    res = run(["resume", str(out), "--quiet"])
    assert res.returncode == 0, err(res)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["final_axial_strain"] > 0.0099
    assert not staging.exists()
    assert sorted(os.listdir(tmp_path)) == ["c.toml", "out"]


def test_failed_or_refused_rerun_leaves_earlier_results_untouched(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    out = tmp_path / "out"
    assert run(["run", cfg, "--out", str(out), "--quiet"]).returncode == 0
    before = tree(out)
    # A numerical blow-up (forced time step far above critical): exit 1.
    failed = run(["run", cfg, "--out", str(out), "--quiet", "--set", "solver.dt=4e-6", "--set", "solver.force_dt=true"])
    assert failed.returncode == 1, err(failed)
    line = one_line(failed)
    assert "run failed" in line and "left as they were" in line, line
    # An input refused only once the sample exists (dt above the critical step): exit 2.
    refused = run(["run", cfg, "--out", str(out), "--quiet", "--set", "solver.dt=1e-3"])
    assert refused.returncode == 2, err(refused)
    assert tree(out) == before
    assert sorted(os.listdir(tmp_path)) == ["c.toml", "out"]


def test_refused_input_leaves_no_folder(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    proc = run(["run", cfg, "--out", str(tmp_path / "new"), "--quiet", "--set", "solver.dt=1e-3"])
    assert proc.returncode == 2
    assert "solver.dt" in one_line(proc)
    assert sorted(os.listdir(tmp_path)) == ["c.toml"]


def test_folder_that_is_not_grainlab_results_is_refused(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("precious")
    for command in ("run", "check"):
        proc = run([command, cfg, "--set", f'output.dir="{other}"'])
        assert proc.returncode == 2
        line = one_line(proc)
        assert "mine" in line and "not empty" in line
    assert os.listdir(other) == ["thesis.tex"]


def run_as_nobody_if_root():
    """Root ignores permission bits: the read-only checks then run the program as nobody."""
    return {"user": 65534, "group": 65534} if os.geteuid() == 0 else {}


def test_read_only_output_folder_exit_1_naming_it():
    base = tempfile.mkdtemp(prefix="grainlab-ro-")
    try:
        os.chmod(base, 0o755)
        cfg = os.path.join(base, "c.toml")
        with open(cfg, "w") as f:
            f.write(TINY)
        for folder, parent_writable in (("ro-empty", True), ("ro-results", True), ("inside-ro", False)):
            target = os.path.join(base, folder)
            os.mkdir(target)
            if folder == "ro-results":
                with open(os.path.join(target, "config.resolved.toml"), "w") as f:
                    f.write("# earlier results\n")
            out = target if parent_writable else os.path.join(target, "sub")
            os.chmod(base, 0o777 if parent_writable else 0o755)
            os.chmod(target, 0o555)
            proc = run(["run", cfg, "--out", out, "--quiet"], **run_as_nobody_if_root())
            assert proc.returncode == 1, err(proc)
            line = one_line(proc)
            assert folder in line and "Permission denied" in line, line
        for root, dirs, files in os.walk(base):
            for name in dirs + files:
                assert ".tmp" not in name and "grainlab-new" not in name, os.path.join(root, name)
        assert sorted(os.listdir(os.path.join(base, "ro-results"))) == ["config.resolved.toml"]
    finally:
        for root, dirs, _ in os.walk(base):
            for d in dirs:
                os.chmod(os.path.join(root, d), 0o755)
        shutil.rmtree(base)


def test_file_where_a_folder_should_be_exit_1(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    (tmp_path / "afile").write_text("x")
    proc = run(["run", cfg, "--out", str(tmp_path / "afile" / "sub"), "--quiet"])
    assert proc.returncode == 1
    line = one_line(proc)
    assert "afile" in line and "Not a directory" in line
    proc = run(["run", cfg, "--out", str(tmp_path / "afile"), "--quiet"])
    assert proc.returncode == 1 and "Not a directory" in one_line(proc)


# --- checkpoints ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def interrupted(tmp_path_factory):
    """A run killed during shearing, after its second checkpoint: its folder and checkpoint bytes."""
    base = tmp_path_factory.mktemp("interrupted")
    cfg = write(base / "c.toml", TINY.replace("final_axial_strain = 0.003", "final_axial_strain = 0.01"))
    folder = base / "run"
    proc = subprocess.Popen([GRAINLAB, "run", cfg, "--out", str(folder), "--quiet"])
    state = folder / "checkpoint" / "state.bin"
    kill_after_second_checkpoint(proc, state)
    assert not (folder / "summary.json").exists()
    return folder, state.read_bytes()


def resume_with(folder, state_bytes, *extra):
    (folder / "checkpoint" / "state.bin").write_bytes(state_bytes)
    return run(["resume", str(folder), "--quiet", *extra], timeout=120)


def test_checkpoint_bit_flips_and_truncations_are_refused(interrupted):
    folder, good = interrupted
    rng = random.Random(18)
    cases = []
    for _ in range(100):
        pos = rng.randrange(len(good))
        flipped = bytearray(good)
        flipped[pos] ^= 1 << rng.randrange(8)
        cases.append((f"bit flip at byte {pos}", bytes(flipped)))
    for _ in range(20):
        n = rng.randrange(len(good))
        cases.append((f"truncated to {n} bytes", good[:n]))
    try:
        for what, data in cases:
            proc = resume_with(folder, data)
            assert proc.returncode == 2, f"{what}: exit {proc.returncode}\n{err(proc)}"
            line = one_line(proc)
            assert "state.bin" in line, f"{what}: {line}"
            assert not (folder / "summary.json").exists()
    finally:
        (folder / "checkpoint" / "state.bin").write_bytes(good)


def test_checkpoint_next_to_another_config_is_refused(interrupted, tmp_path):
    folder, good = interrupted
    moved = tmp_path / "moved"
    shutil.copytree(folder, moved)
    resolved = moved / "config.resolved.toml"
    resolved.write_text(resolved.read_text().replace("friction_deg = 30.0", "friction_deg = 31.0"))
    proc = run(["resume", str(moved), "--quiet"])
    assert proc.returncode == 2
    line = one_line(proc)
    assert "state.bin" in line and "another config" in line
    # The folder may be moved as a whole: output.dir is not part of the check. A copy resumes.
    whole = tmp_path / "whole copy"
    shutil.copytree(folder, whole)
    proc = run(["resume", str(whole), "--quiet"])
    assert proc.returncode == 0, err(proc)
    assert json.loads((whole / "summary.json").read_text())["status"] == "completed"


def test_old_checkpoint_format_and_foreign_file(interrupted, tmp_path):
    folder, good = interrupted
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    for data, fragment in ((b'{"format":"grainlab-checkpoint-2"}\n' + good[200:], "earlier checkpoint format"),
                           (b"\x89PNG\r\n\x1a\n" + good[8:], "not a grainlab checkpoint"),
                           (b"", "truncated")):
        proc = resume_with(copy, data)
        assert proc.returncode == 2 and fragment in one_line(proc), err(proc)
    shutil.rmtree(copy / "checkpoint")
    (copy / "checkpoint").mkdir()
    (copy / "checkpoint" / "state.bin").mkdir()  # a folder where the file should be
    proc = run(["resume", str(copy), "--quiet"])
    assert proc.returncode == 2 and "a directory" in one_line(proc)


# --- bounded input --------------------------------------------------------------------------------

@pytest.mark.parametrize("text", [
    "a = " + "[" * 100000 + "]" * 100000 + "\n",
    "a = " + "{ b = " * 100000 + "1" + " }" * 100000 + "\n",
    "[" + ".".join(["t"] * 100000) + "]\nx = 1\n",
    ".".join(["k"] * 100000) + " = 1\n",
], ids=["arrays", "inline-tables", "table-header", "dotted-key"])
def test_deep_nesting_is_refused_before_parsing(tmp_path, text):
    proc = run(["check", write(tmp_path / "deep.toml", text)])
    assert proc.returncode == 2, err(proc)
    line = one_line(proc)
    assert "deep.toml" in line and "nested deeper than 64" in line and len(line) < 300


def test_deep_set_value_is_refused(tmp_path):
    cfg = write(tmp_path / "c.toml", TINY)
    proc = run(["check", cfg, "--set", "sample.grading=" + "[" * 100000])
    assert proc.returncode == 2 and "nested deeper than 64" in one_line(proc)
    proc = run(["check", cfg, "--set", ".".join(["k"] * 60000) + "=1"])
    assert proc.returncode == 2 and "nested deeper than 64" in one_line(proc)


@pytest.mark.parametrize("setting,key", [
    ("sample.n_particles = 9007199254740993", "sample.n_particles"),
    ("sample.density = 9007199254740993", "sample.density"),
    ("sample.e0 = 9223372036854775807", "sample.e0"),
    ("test.confining_pressure = -9223372036854775808", "test.confining_pressure"),
    ("sample.seed = 99999999999999999999", "c.toml"),
    ("sample.e0 = nan", "sample.e0"),
    ("test.final_axial_strain = inf", "test.final_axial_strain"),
    ('sample.grading = { type = "curve", diameters = [2e-3, nan], passing = [0.0, 100.0] }', "sample.grading.diameters"),
    ('sample.grading = { type = "curve", diameters = [2e-3, 8e-3], passing = [0.0, inf] }', "sample.grading.passing"),
    ('sample.grading = { type = "uniform", d_min = 1e-3, d_max = inf }', "sample.grading.d_max"),
], ids=lambda v: v if len(v) < 30 else v[:30])
def test_huge_and_non_finite_numbers(tmp_path, setting, key):
    section, assignment = setting.split(".", 1)
    cfg = write(tmp_path / "c.toml", f"[{section}]\n{assignment}\n")
    proc = run(["check", cfg])
    assert proc.returncode == 2, err(proc)
    line = one_line(proc)
    assert key in line and "bad optional access" not in line, line


@pytest.mark.parametrize("rows,line_no", [
    ("nan\n0.004\n", 1),
    ("d\n0.004\ninf\n", 3),
    ("0.004\n1e999\n", 2),
    ("0.004\n-0.002\n", 2),
    ("0.004\n0.005abc\n", 2),
])
def test_non_finite_values_in_a_grading_list(tmp_path, rows, line_no):
    (tmp_path / "d.csv").write_text(rows)
    cfg = write(tmp_path / "c.toml", TINY.replace('{ type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }',
                                                  '{ type = "list", file = "d.csv" }'))
    proc = run(["check", cfg])
    assert proc.returncode == 2, err(proc)
    line = one_line(proc)
    assert "sample.grading.file" in line and "d.csv" in line and f"line {line_no}" in line, line


@pytest.mark.parametrize("rows,line_no", [("sphericity\n0.8\nnan\n", 3), ("bin_low,bin_high,frequency\n0.5,inf,1\n", 2)])
def test_non_finite_values_in_a_sphericity_file(tmp_path, rows, line_no):
    (tmp_path / "s.csv").write_text(rows)
    proc = run(["check", "preset:rorato-sphericity", "--set",
                f'contact.sphericity={{ file = "{tmp_path / "s.csv"}", k = -4.0 }}'])
    assert proc.returncode == 2, err(proc)
    line = one_line(proc)
    assert "contact.sphericity.file" in line and f"line {line_no}" in line, line


def test_20_mb_values(tmp_path):
    big = "x" * (20 << 20)
    proc = run(["check", write(tmp_path / "big.toml", f'[output]\ndir = "{big}"\n')])
    assert proc.returncode == 2
    line = one_line(proc)
    assert "big.toml" in line and "limit" in line and len(line) < 300
    # Below the config limit, a long value is echoed cut.
    proc = run(["check", write(tmp_path / "long.toml", f'[sample]\nnote = "{"y" * 900_000}"\n')])
    assert proc.returncode == 2
    line = one_line(proc)
    assert "sample.note" in line and "..." in line and len(line) < 400
    # A 20 MB line in a list file: refused naming the file and line, the value cut.
    (tmp_path / "d.csv").write_text("0.004\n" + "7" * (20 << 20) + "z\n")
    cfg = write(tmp_path / "c.toml", TINY.replace('{ type = "uniform", d_min = 4.0e-3, d_max = 6.0e-3 }',
                                                  '{ type = "list", file = "d.csv" }'))
    proc = run(["check", cfg])
    assert proc.returncode == 2
    line = one_line(proc)
    assert "line 2" in line and len(line) < 400


@pytest.mark.parametrize("what", ["directory", "dev-zero", "fifo", "missing", "too-large"])
@pytest.mark.parametrize("key", ["grading", "sphericity", "packing"])
def test_check_reads_every_named_file_and_only_regular_ones(tmp_path, what, key):
    target = {"directory": str(tmp_path), "dev-zero": "/dev/zero", "fifo": str(tmp_path / "fifo"),
              "missing": str(tmp_path / "none.csv"), "too-large": str(tmp_path / "huge.csv")}[what]
    if what == "fifo":
        os.mkfifo(target)
    if what == "too-large":
        with open(target, "wb") as f:  # sparse: 1 GiB + 1 byte, more than any of the limits
            f.truncate((1 << 30) + 1)
    if key == "grading":
        args = ["check", write(tmp_path / "c.toml", TINY), "--set", f'sample.grading={{ type = "list", file = "{target}" }}']
        name = "sample.grading.file"
    elif key == "sphericity":
        args = ["check", "preset:rorato-sphericity", "--set", f'contact.sphericity={{ file = "{target}", k = -4.0 }}']
        name = "contact.sphericity.file"
    else:
        args = ["check", write(tmp_path / "c.toml", TINY), "--set", f'sample.packing="{target}"']
        name = "sample.packing"
    proc = run(args, timeout=20)
    assert proc.returncode == 2, err(proc)
    line = one_line(proc)
    expected = {"directory": "a directory", "dev-zero": "character device", "fifo": "FIFO", "missing": "not found",
                "too-large": "limit"}[what]
    assert name in line and expected in line, line


# --- packing files --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def packing(tmp_path_factory):
    """packing.txt of a real run (format 2)."""
    base = tmp_path_factory.mktemp("packing")
    cfg = write(base / "c.toml", TINY.replace('type = "triaxial"', 'type = "isotropic"'))
    proc = run(["run", cfg, "--out", str(base / "run"), "--quiet"])
    assert proc.returncode == 0, err(proc)
    return base / "run" / "packing.txt"


def check_packing(tmp_path, text_or_bytes, name="p.txt"):
    path = tmp_path / name
    if isinstance(text_or_bytes, bytes):
        path.write_bytes(text_or_bytes)
    else:
        path.write_text(text_or_bytes)
    return run(["check", write(tmp_path / "c.toml", TINY), "--set", f'sample.packing="{path}"'])


def test_packing_format_2_is_written_and_read_back(packing, tmp_path):
    lines = packing.read_text().splitlines()
    assert lines[0] == "# grainlab-packing 2"
    header = [l for l in lines if l.startswith("#")]
    assert [h.split()[1] for h in header[1:]] == ["program", "comment", "boundary", "walls", "particles", "columns",
                                                  "xxh64"]
    assert "# columns id shape a b c x y z qw qx qy qz" in lines
    rows = [l.split() for l in lines if not l.startswith("#")]
    assert len(rows) == 100 and all(len(r) == 12 and r[1] == "sphere" and r[2] == r[3] == r[4] for r in rows)
    assert [int(r[0]) for r in rows] == list(range(100))
    assert run(["check", write(tmp_path / "c.toml", TINY), "--set", f'sample.packing="{packing}"']).returncode == 0


def body_rows(packing):
    return [l for l in packing.read_text().splitlines() if not l.startswith("#")]


def walls_line(packing):
    return next(l for l in packing.read_text().splitlines() if l.startswith("# walls"))


def test_packing_format_1_and_a_hand_written_format_2_are_accepted(packing, tmp_path):
    rows = [r.split() for r in body_rows(packing)]
    walls = walls_line(packing)[len("# walls "):]
    v1 = "# a packing of grainlab 0.1\n" + walls + "\n" + "".join(f"{r[2]} {r[5]} {r[6]} {r[7]}\n" for r in rows)
    assert check_packing(tmp_path, v1).returncode == 0
    # Hand-written: no checksum line, keys in another order, ids not 0..N-1.
    v2 = ("# grainlab-packing 2\n# particles 100\n# boundary walls\n# walls " + walls +
          "\n# comment by hand\n# program my-script\n# columns id shape a b c x y z qw qx qy qz\n" +
          "".join(f"{1000 - i} sphere {' '.join(r[2:])}\n" for i, r in enumerate(rows)))
    proc = check_packing(tmp_path, v2)
    assert proc.returncode == 0, err(proc)


def header(*lines):
    return ["# grainlab-packing 2", "# program by hand", "# comment a test", *lines,
            "# columns id shape a b c x y z qw qx qy qz"]


def hand_written(packing, edit_rows=None, head=None):
    """Text of a packing without a checksum: `head` (default: that of `packing`) and its rows."""
    rows = body_rows(packing)
    if edit_rows:
        rows = edit_rows(rows)
    head = head or header("# boundary walls", walls_line(packing), f"# particles {len(rows)}")
    return "\n".join(head + rows) + "\n"


def set_field(rows, i, col, value):
    r = rows[i].split()
    r[col] = value
    rows[i] = " ".join(r)
    return rows


def test_packing_content_is_validated(packing, tmp_path):
    walls = walls_line(packing)
    row = len(header("# boundary walls", walls, "# particles 100")) + 1  # line of the first row
    cases = [
        (hand_written(packing, head=header("# boundary periodic", "# cell 0.05 0 0 0 0.05 0 0 0 0.05",
                                           "# particles 100")), "", "the packing's boundary is a periodic cell but "
         "test.boundary = \"walls\""),
        (hand_written(packing, lambda r: set_field(r, 2, 8, "0.9")), f"line {row + 2}", "unit quaternion"),
        (hand_written(packing, lambda r: set_field(set_field(r, 2, 1, "ellipsoid"), 2, 2, "0.0001")),
         f"line {row + 2}", "a >= b >= c"),
        (hand_written(packing, lambda r: set_field(r, 2, 4, "0.001")), f"line {row + 2}", "a sphere has a = b = c"),
        (hand_written(packing, lambda r: set_field(r, 3, 0, "5")), f"line {row + 5}", "not unique"),
        (hand_written(packing, lambda r: set_field(r, 3, 5, "nan")), f"line {row + 3}", "finite"),
        (hand_written(packing, lambda r: set_field(r, 3, 6, "1e999")), f"line {row + 3}", "finite"),
        (hand_written(packing, lambda r: set_field(r, 3, 0, "-3")), f"line {row + 3}", "unsigned integer"),
        (hand_written(packing, lambda r: set_field(r, 3, 5, "9")), f"line {row + 3}", "outside the walls"),
        (hand_written(packing, lambda r: set_field(r, 3, 1, "cube")), f"line {row + 3}", "shape"),
        (hand_written(packing, lambda r: r[:3] + [r[3] + " 7"] + r[4:]), f"line {row + 3}", "12 columns"),
        (hand_written(packing, lambda r: r + ["# late"]), f"line {row + 100}", "header line after"),
        (hand_written(packing, head=header("# boundary walls", walls, "# particles 101")), "", "100 particle rows, "
         "the header says 101"),
        (hand_written(packing, head=header("# boundary walls", walls, "# particles 100000000")), "line 6",
         "must be an integer"),
        (hand_written(packing, head=header("# boundary walls", walls, "# particles 5000000")), "line 6", "cannot fit"),
        (hand_written(packing, head=header("# boundary walls", walls, "# particles 100", "# colour red")), "line 7",
         "unknown header key"),
        (hand_written(packing, head=header("# boundary walls", walls, "# boundary walls", "# particles 100")),
         "line 6", "given twice"),
        (hand_written(packing, head=header("# boundary walls", "# particles 100")), "", "\"walls\" missing"),
        (hand_written(packing, head=header("# boundary walls", "# walls 0 1 0 -1 0 1", "# particles 100")), "line 5",
         "upper wall"),
        (hand_written(packing, head=header("# boundary periodic", "# cell 1 0 0 0 -1 0 0 0 1", "# particles 100")),
         "line 5", "det H > 0"),
        (hand_written(packing, head=["# grainlab-packing 2", "# program x", "# boundary walls", walls,
                                     "# particles 100", "# columns id shape a b c x y z qw qx qy qz"]), "",
         "\"comment\" missing"),
        ("# grainlab-packing 3\n", "line 1", "version 3 is not supported"),
        (packing.read_text().replace("# xxh64 ", "# xxh64 0", 1), "line 8", "16 hexadecimal digits"),
        (packing.read_text().replace("# xxh64 ", "# xxh64 ", 1).replace(" sphere ", " sphere  ", 1), "line 8",
         "checksum mismatch"),
        ("", "", "empty file"),
    ]
    for text, where, fragment in cases:
        proc = check_packing(tmp_path, text)
        assert proc.returncode == 2, (fragment, err(proc))
        line = one_line(proc)
        assert "sample.packing" in line and "p.txt" in line and where in line and fragment in line, (fragment, line)


def test_packing_with_an_ellipsoid_row_is_accepted(packing, tmp_path):
    """Ellipsoids are a shape of the engine: a row with a >= b >= c is read as one (no refusal)."""
    proc = check_packing(tmp_path, hand_written(packing, lambda r: set_field(r, 4, 1, "ellipsoid")))
    assert proc.returncode == 0, err(proc)


def test_packing_bit_flips_and_truncations_are_refused(packing, tmp_path):
    """Flips anywhere in the file: the checksum covers every byte but its own line (the header with
    the walls, program and comment, and the rows), and the checksum line itself is checked for form
    and against the rest."""
    good = packing.read_bytes()
    positions = list(range(len(good)))
    rng = random.Random(16)
    cases = []
    for _ in range(100):
        pos = rng.choice(positions)
        flipped = bytearray(good)
        flipped[pos] ^= 1 << rng.randrange(8)
        cases.append((f"bit flip at byte {pos}", bytes(flipped)))
    for _ in range(20):
        cases.append(("truncated", good[:rng.randrange(len(good) - 1)]))
    for what, data in cases:
        proc = check_packing(tmp_path, data)
        assert proc.returncode == 2, f"{what}: exit {proc.returncode}\n{err(proc)}"
        line = one_line(proc)
        assert "sample.packing" in line and "p.txt" in line, f"{what}: {line}"


def test_peer_scripts_read_packing_format_2_and_1(packing, tmp_path):
    """bench/peer/packing_file.py (read by the YADE peers) gives the walls and spheres grainlab wrote,
    and refuses a corrupted file."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "packing_file", os.path.join(os.path.dirname(__file__), "..", "..", "bench", "peer", "packing_file.py"))
    pf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pf)
    planes, spheres = pf.read_packing(str(packing))
    rows = [r.split() for r in body_rows(packing)]
    assert planes == [float(v) for v in walls_line(packing).split()[2:]]
    assert spheres == [(float(r[2]), float(r[5]), float(r[6]), float(r[7])) for r in rows]
    v1 = tmp_path / "v1.txt"
    v1.write_text("# v1\n" + " ".join(map(str, planes)) + "\n" + "".join(" ".join(map(repr, s)) + "\n" for s in spheres))
    assert pf.read_packing(str(v1)) == (planes, spheres)
    spoilt = tmp_path / "spoilt.txt"
    spoilt.write_text(packing.read_text().replace(" sphere ", " sphere  ", 1))
    with pytest.raises(pf.PackingError, match="checksum"):
        pf.read_packing(str(spoilt))
