"""Fuzzer of hostile input (issue 16): seeded malformed configs, --set values, list files, packing
files and checkpoints, each invalid by construction. Every case must end with exit 2 and one short
line on stderr naming the key or the file: never a signal, never a hang, no files written on a
refused input. Most cases use `grainlab check` (what a run does first); checkpoints use `resume`
and a handful of real `run`s check the output folder.

CI runs about 1300 cases (~1 min on 2 cores). For a longer search:
    GRAINLAB_FUZZ_SCALE=20 GRAINLAB_FUZZ_SEED=7 python3 -m pytest tests/python/test_fuzz.py
(SCALE multiplies the number of cases, SEED changes them; a failure prints the case to replay)."""
import json
import os
import random
import shutil
import subprocess

import pytest

from conftest import GRAINLAB, TINY_CONFIG as BASE

SCALE = max(1, int(os.environ.get("GRAINLAB_FUZZ_SCALE", "1")))
SEED = int(os.environ.get("GRAINLAB_FUZZ_SEED", "16"))
TIMEOUT = 20  # [s] per invocation: more is a hang


NUMBER_KEYS = [
    "sample.density", "sample.e0", "sample.e0_tolerance", "sample.initial_void_ratio", "sample.prep_stiffness_factor",
    "sample.prep_damping", "sample.prep_friction_deg", "contact.young", "contact.poisson", "contact.friction_deg",
    "contact.beta", "contact.eta", "contact.wall_friction_deg", "test.confining_pressure", "test.axial_strain_rate",
    "test.final_axial_strain", "solver.damping", "solver.dt_factor", "solver.dt", "solver.unbalanced_tolerance",
    "solver.stress_tolerance", "solver.servo_gain", "solver.servo_integral_steps", "solver.servo_max_speed", "test.servo_max_speed",
    "solver.skin_fraction", "output.record_every_strain", "output.checkpoint_every", "output.vtk_every_strain",
    "output.band_factor", "output.band_strain_window", "test.platen_friction_deg",
]
INTEGER_KEYS = ["sample.n_particles", "sample.seed", "sample.prep_ramp_steps", "solver.threads", "solver.max_steps"]
CHOICE_KEYS = {"contact.model": ["kozicki", "rolling-linear"], "test.type": ["isotropic", "triaxial"],
               "test.boundary": ["walls"]}
BOOL_KEYS = ["solver.force_dt", "output.plots", "output.save_packing"]
SECTIONS = ["sample", "contact", "test", "solver", "output"]

# Values no number key accepts: every range is finite and starts at 0 or above.
BAD_NUMBERS = ["nan", "+nan", "-nan", "inf", "+inf", "-inf", "1e300", "-1e300", "-1", "1e400", "-0.5e999", '"0.5"',
               "true", "[0.5]", "{ v = 0.5 }", "1979-05-27", "07:32:00", "''", "[]", "{}", "9223372036854775807"]
BAD_INTEGERS = ["2.5", "-1", "-9223372036854775808", "nan", "inf", "1e3", '"100"', "false", "[100]", "{}", "0.0"]


def unicode_text(rng, n):
    alphabet = "aé€𝄞\u200b\u202eЖ中🙂\\\"'=#[]{}., \t"
    return "".join(rng.choice(alphabet) for _ in range(n))


def garbage(rng, n):
    return bytes(rng.randrange(256) for _ in range(n))


def toml_string(s):
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t") + '"'


def nested(rng, depth):
    kind = rng.choice(["array", "table"])
    if kind == "array":
        return "[" * depth + "1" + "]" * depth
    return "{ a = " * depth + "1" + " }" * depth


class Cases:
    """Generates (name, files {relpath: bytes}, argv after the program, fragments one of which the
    message must contain). `{dir}` in an argument is replaced by the case's folder."""

    def __init__(self, rng):
        self.rng = rng

    def set_value(self):
        rng = self.rng
        pick = rng.random()
        if pick < 0.35:
            key = rng.choice(NUMBER_KEYS)
            value = rng.choice(BAD_NUMBERS)
        elif pick < 0.5:
            key = rng.choice(INTEGER_KEYS)
            value = rng.choice(BAD_INTEGERS)
        elif pick < 0.6:
            key = rng.choice(list(CHOICE_KEYS))
            value = rng.choice([toml_string(unicode_text(rng, rng.randrange(1, 12))), "1", "true", "[]",
                                toml_string(CHOICE_KEYS[key][0].upper()), '""'])
        elif pick < 0.67:
            key = rng.choice(BOOL_KEYS)
            value = rng.choice(["1", "0", '"true"', "yes", "[true]", "nan", "True"])
        elif pick < 0.75:
            section = rng.choice(SECTIONS)
            key = section + "." + rng.choice(["", "x_"]) + unicode_text(rng, rng.randrange(1, 10)).replace(
                ".", "_").replace("=", "_").strip() + "z"
            value = rng.choice(["1", '"x"', "nan", "[1, 2]"])
            return "set unknown key", {}, ["check", "{dir}/c.toml", "--set", f"{key}={value}"], [section + "."]
        elif pick < 0.8:
            key = rng.choice(NUMBER_KEYS + INTEGER_KEYS)
            value = nested(rng, rng.randrange(65, 3000))
            return ("set deep", {}, ["check", "{dir}/c.toml", "--set", f"{key}={value}"], [key, "--set"])
        elif pick < 0.87:
            key = rng.choice(NUMBER_KEYS + INTEGER_KEYS)
            # Bytes reach the program unchanged; the leading 0xff makes it no TOML value at all.
            arg = (key + "=").encode() + b"\xff" + garbage(rng, rng.randrange(0, 40)).replace(b"\0", b"")
            return ("set garbage", {}, ["check", "{dir}/c.toml", "--set", arg], [key])
        elif pick < 0.93:
            key = rng.choice(NUMBER_KEYS)
            value = toml_string("9" * rng.randrange(1000, 100000))
        else:
            section = rng.choice(["zz", "Sample", "sample ", "ñ", "output2"])
            key = section + ".x"
            value = "1"
            return ("set unknown section", {}, ["check", "{dir}/c.toml", "--set", f"{key}={value}"],
                    [section.strip()[:2], "--set"])
        return ("set", {}, ["check", "{dir}/c.toml", "--set", f"{key}={value}"], [key])

    def config_file(self):
        rng = self.rng
        pick = rng.random()
        lines = BASE.splitlines()
        if pick < 0.2:  # a key given twice
            i = rng.choice([k for k, l in enumerate(lines) if "=" in l])
            lines.insert(i + 1, lines[i])
            return "duplicate key", {"c.toml": "\n".join(lines).encode()}, ["check", "{dir}/c.toml"], ["c.toml"]
        if pick < 0.35:  # garbage bytes in place of a value
            i = rng.choice([k for k, l in enumerate(lines) if "=" in l])
            key = lines[i].split("=")[0].strip()
            junk = b"\xfe" + garbage(rng, rng.randrange(0, 30)).replace(b"\n", b"")
            text = "\n".join(lines[:i]).encode() + b"\n" + key.encode() + b" = " + junk + b"\n" + \
                "\n".join(lines[i + 1:]).encode()
            return "garbage value", {"c.toml": text}, ["check", "{dir}/c.toml"], ["c.toml", key]
        if pick < 0.45:  # a binary file
            return ("binary", {"c.toml": b"\xff" + garbage(rng, rng.randrange(0, 4000))}, ["check", "{dir}/c.toml"],
                    ["c.toml"])
        if pick < 0.6:  # deep nesting of several kinds
            depth = rng.randrange(65, 100000)
            text = rng.choice([
                "a = " + nested(rng, depth) + "\n",
                "[" + ".".join(["t"] * depth) + "]\n",
                ".".join(["k"] * depth) + " = 1\n",
                "[sample]\ngrading = " + nested(rng, depth) + "\n",
            ])
            return "deep file", {"c.toml": text.encode()}, ["check", "{dir}/c.toml"], ["c.toml"]
        if pick < 0.7:  # an unknown key with a unicode or very long name
            section = rng.choice(SECTIONS)
            name = rng.choice([unicode_text(rng, 8), "k" * rng.randrange(100, 5000)])
            text = BASE.replace(f"[{section}]", f"[{section}]\n{toml_string(name)} = 1")
            if f"[{section}]" not in BASE:
                text = BASE + f"\n[{section}]\n{toml_string(name)} = 1\n"
            return "unknown key", {"c.toml": text.encode()}, ["check", "{dir}/c.toml"], [section + "."]
        if pick < 0.8:  # a number key with a non-finite or out-of-range value in the file (or given twice)
            key = rng.choice(NUMBER_KEYS)
            section, name = key.split(".")
            line = f"{name} = {rng.choice(BAD_NUMBERS)}"
            text = (BASE.replace(f"[{section}]", f"[{section}]\n{line}") if f"[{section}]" in BASE
                    else BASE + f"\n[{section}]\n{line}\n")
            return "bad number", {"c.toml": text.encode()}, ["check", "{dir}/c.toml"], [key, "c.toml"]
        if pick < 0.9:  # a huge string value
            n = rng.choice([2 << 20, 20 << 20])
            return ("huge file", {"c.toml": b'[output]\ndir = "' + b"d" * n + b'"\n'}, ["check", "{dir}/c.toml"],
                    ["c.toml"])
        # output.dir refused: empty, or with a NUL character
        value = rng.choice(['""', '"a\\u0000b"', "''"])
        return "output.dir", {"c.toml": (BASE + f"dir = {value}\n").encode()}, ["check", "{dir}/c.toml"], ["output.dir"]

    def grading(self):
        rng = self.rng
        pick = rng.random()
        if pick < 0.5:
            d, p = rng.choice([
                ("[2e-3, 1e-3]", "[0.0, 100.0]"), ("[2e-3, 8e-3]", "[0.0, 90.0]"), ("[2e-3]", "[100.0]"),
                ("[2e-3, 8e-3, 9e-3]", "[0.0, 100.0]"), ("[-2e-3, 8e-3]", "[0.0, 100.0]"), ("[2e-3, nan]", "[0, 100]"),
                ("[2e-3, 8e-3]", "[0.0, inf]"), ("[2e-3, 4e-3, 8e-3]", "[0.0, 60.0, 50.0]"), ("[]", "[]"),
                ('["2e-3", 8e-3]', "[0.0, 100.0]"), ("[2e-3, 2e-3]", "[0.0, 100.0]"), ("[0, 8e-3]", "[0.0, 100.0]"),
            ])
            value = f'{{ type = "curve", diameters = {d}, passing = {p} }}'
            return "grading curve", {}, ["check", "{dir}/c.toml", "--set", f"sample.grading={value}"], ["sample.grading"]
        if pick < 0.6:
            value = rng.choice(['{ type = "uniform", d_min = 5e-3, d_max = 1e-3 }', '{ type = "uniform", d_min = 0 }',
                                '{ type = "sieve" }', '{ type = "uniform", d_min = 1e-3, d_max = 2e-3, extra = 1 }',
                                '{ d_min = 1e-3 }', '{ type = "list" }', '"uniform"'])
            return "grading table", {}, ["check", "{dir}/c.toml", "--set", f"sample.grading={value}"], ["sample.grading"]
        rows = [str(rng.uniform(1e-3, 8e-3)) for _ in range(rng.randrange(1, 30))]
        bad = rng.choice(["nan", "inf", "-inf", "-0.004", "0", "1e999", "abc", "0.004x", garbage(rng, 8).hex() + "\xff",
                          "\u00a0", "0x1p-9", "#"])
        pos = rng.randrange(1, len(rows) + 1)
        rows.insert(pos, bad)
        if bad == "#":  # a list of comments only: no diameters
            rows = ["# only comments"] * 3
        text = ("d\n" if rng.random() < 0.5 else "") + "\n".join(rows) + "\n"
        if rng.random() < 0.1:
            text = "d\n\udcff" + garbage(rng, rng.randrange(10, 300)).decode("latin-1")
        return ("grading list", {"d.csv": text.encode("utf-8", "surrogateescape")},
                ["check", "{dir}/c.toml", "--set", 'sample.grading={ type = "list", file = "{dir}/d.csv" }'],
                ["sample.grading.file"])

    def sphericity(self):
        rng = self.rng
        text = rng.choice([
            "", "psi\n0.8\n", "sphericity\n", "sphericity\n0.8\nnan\n", "sphericity\n0.8\n-0.5\n", "sphericity\n0\n",
            "sphericity\ninf\n", "sphericity\n0.8x\n", "bin_low,bin_high,frequency\n0.5,0.4,1\n",
            "bin_low,bin_high,frequency\n0.5,0.6,0\n", "bin_low,bin_high,frequency\n0.5,0.6,-1\n",
            "bin_low,bin_high,frequency\n0.5,0.6\n", "bin_low,bin_high,frequency\n0.5,nan,1\n",
            "bin_low,bin_high\n0.5,0.6\n", garbage(rng, 50).decode("latin-1"),
        ])
        if text == "sphericity\n0.8\n":
            text += "1e999\n"
        k = rng.choice(["-4.0"] * 6 + ["nan", "inf", '"x"', None])
        fields = ['file = "{dir}/s.csv"'] + ([f"k = {k}"] if k else [])
        expect = ["contact.sphericity.k"] if k in ("nan", "inf", '"x"', None) else ["contact.sphericity.file"]
        return ("sphericity", {"s.csv": text.encode("utf-8", "surrogateescape")},
                ["check", "preset:rorato-sphericity", "--set", "contact.sphericity={ " + ", ".join(fields) + " }"],
                expect + ["contact.sphericity"])

    def packing(self):
        rng = self.rng
        n = rng.randrange(2, 25)
        walls = [0.0, 0.02, 0.0, 0.02, 0.0, 0.02]
        rows = [f"{i} sphere 0.002 0.002 0.002 {rng.uniform(0.003, 0.017)} {rng.uniform(0.003, 0.017)} "
                f"{rng.uniform(0.003, 0.017)} 1 0 0 0" for i in range(n)]
        head = ["# grainlab-packing 2", "# program fuzz", "# comment fuzzed", "# boundary walls",
                "# walls " + " ".join(map(str, walls)), f"# particles {n}", "# columns id shape a b c x y z qw qx qy qz"]
        pick = rng.random()
        if pick < 0.35:  # one field of a row made invalid
            i = rng.randrange(n)
            f = rows[i].split()
            col = rng.randrange(12)
            f[col] = rng.choice({
                0: ["x", "-1", "0.5", "", "1e3", str((i + 1) % n)],  # the last: an id given twice
                1: ["cube", "", "Sphere", "ellipsoid"],              # an "ellipsoid" of a = b = c: unsupported
                2: ["nan", "inf", "-0.002", "0", "x", "0.001"],      # 0.001: a < b
                3: ["nan", "inf", "-0.002", "0", "x", "0.003"],      # 0.003: a < b
                4: ["nan", "inf", "-0.002", "0", "x", "0.003"],      # 0.003: b < c
                5: ["nan", "inf", "0.5", "-0.5", "x", "1e999"],      # 0.5: outside the walls
                6: ["nan", "inf", "0.5", "-0.5", "x", "1e999"],
                7: ["nan", "inf", "0.5", "-0.5", "x", "1e999"],
                8: ["nan", "0.5", "x", "2", "-inf"],                 # 0.5: not a unit quaternion
                9: ["nan", "0.5", "x", "2", "1"],
                10: ["nan", "0.5", "x", "2", "1"],
                11: ["nan", "0.5", "x", "2", "1"],
            }[col])
            rows[i] = " ".join(x for x in f if x)  # an empty field: one column fewer
        elif pick < 0.5:  # a header line removed, spoilt, repeated or unknown
            k = rng.randrange(1, len(head))
            what = rng.choice(["remove", "spoil", "repeat", "unknown"])
            if what == "remove":
                del head[k]
            elif what == "repeat":
                head.insert(k, head[k])
            elif what == "unknown":
                head.insert(k, "# " + rng.choice(["colour red", "xxh32 00", "Particles 3", unicode_text(rng, 6) + "q"]))
            else:
                head[k] = {1: "#program fuzz", 2: "#comment", 3: "# boundary cell", 4: "# walls 0 1 0 -1 0 1",
                           5: "# particles " + rng.choice(["-1", "0", "1e3", str(n + 1), "99999999999", "x", ""]),
                           6: "# columns id shape a b c x y z"}[k]
        elif pick < 0.6:  # a row missing, or one too many
            rows = rows[:-1] if rng.random() < 0.5 else rows + [rows[0].replace("0 sphere", f"{n} sphere", 1)]
        elif pick < 0.67:  # another version
            head[0] = rng.choice(["# grainlab-packing 3", "# grainlab-packing", "# grainlab-packing 2 2",
                                  "# grainlab-packing two"])
        elif pick < 0.75:  # garbage
            return ("packing garbage", {"p.txt": b"\xff" + garbage(rng, rng.randrange(0, 2000))}, self._packing_args(),
                    ["sample.packing"])
        elif pick < 0.87:  # format 1 with one line made invalid
            v1 = ["# v1", " ".join(map(str, walls))] + [" ".join(r.split()[i] for i in (2, 5, 6, 7)) for r in rows]
            k = rng.randrange(1, len(v1))
            v1[k] = rng.choice(["nan 0.01 0.01 0.01", "0.001 0.01 0.01", "0.001 0.01 0.01 0.01 5",
                                "-0.001 0.01 0.01 0.01", "0.001 9 0.01 0.01", "0.001 0.01 x 0.01"])
            return "packing v1", {"p.txt": ("\n".join(v1) + "\n").encode()}, self._packing_args(), ["sample.packing"]
        elif pick < 0.94:  # two grains overlapping deeply or coincident (issue 28: "numerical instability")
            i, j = rng.sample(range(n), 2) if n > 1 else (0, 0)
            fi, fj = rows[i].split(), rows[j].split()
            shift = rng.choice([0.0, 1e-12, 2e-4, 1e-3])  # centre distance; radii 0.002
            fj[5:8] = [str(float(fi[5]) + shift), fi[6], fi[7]]
            rows[j] = " ".join(fj)
            if i == j:
                rows.append(rows[0].replace("0 sphere", f"{n} sphere", 1))
                head[5] = f"# particles {n + 1}"
        else:  # a periodic cell under a walls test, or an ellipsoid whose axes are out of order
            if rng.random() < 0.5:
                head[3] = "# boundary periodic"
                head[4] = "# cell 0.02 0 0 0 0.02 0 0 0 0.02"
            else:
                rows[0] = rows[0].replace("sphere 0.002 0.002 0.002", "ellipsoid 0.001 0.002 0.003")
        return ("packing", {"p.txt": ("\n".join(head + rows) + "\n").encode()}, self._packing_args(),
                ["sample.packing"])

    def _packing_args(self):
        return ["check", "{dir}/c.toml", "--set", 'sample.packing="{dir}/p.txt"']

    def missing_paths(self):
        rng = self.rng
        where = rng.choice(["{dir}/no/such/folder/f.csv", "/proc/self/nothing/f.csv", "{dir}/" + "x" * 5000 + "/f.csv",
                            "{dir}/c.toml/inside.csv"])
        key, value, expect = rng.choice([
            ("sample.grading", f'{{ type = "list", file = "{where}" }}', "sample.grading.file"),
            ("sample.packing", f'"{where}"', "sample.packing"),
        ])
        return "missing path", {}, ["check", "{dir}/c.toml", "--set", f"{key}={value}"], [expect]


def expand(args, folder):
    out = []
    for a in args:
        if isinstance(a, bytes):
            out.append(a.replace(b"{dir}", os.fsencode(folder)))
        else:
            out.append(a.replace("{dir}", str(folder)))
    return out


def assert_refused(proc, fragments, case):
    assert proc.returncode >= 0, f"signal {-proc.returncode}: {case}"
    stderr = proc.stderr.decode("utf-8", "replace")
    assert proc.returncode == 2, f"exit {proc.returncode}: {case}\n{stderr[:2000]}"
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, f"{len(lines)} lines: {case}\n{stderr[:2000]}"
    assert len(lines[0]) <= 700, f"a line of {len(lines[0])} characters: {case}"
    assert any(f in lines[0] for f in fragments), f"names none of {fragments}: {case}\n{lines[0]}"


def run_case(folder, name, files, args, fragments):
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir()
    (folder / "c.toml").write_text(BASE)
    for rel, data in files.items():
        (folder / rel).write_bytes(data)
    argv = expand(args, folder)
    try:
        proc = subprocess.run([GRAINLAB, *argv], capture_output=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        pytest.fail(f"hang (> {TIMEOUT} s): {name} {argv!r:.500}")
    assert_refused(proc, fragments, f"{name} {argv!r:.500}")


GENERATORS = [("set_value", 520), ("config_file", 260), ("grading", 170), ("sphericity", 80), ("packing", 230),
              ("missing_paths", 40)]


@pytest.mark.parametrize("generator,count", GENERATORS, ids=[g for g, _ in GENERATORS])
def test_fuzz_check(tmp_path, generator, count):
    rng = random.Random(f"{SEED}-{generator}")
    cases = Cases(rng)
    for i in range(count * SCALE):
        name, files, args, fragments = getattr(cases, generator)()
        run_case(tmp_path / "case", f"{generator} #{i} (seed {SEED}): {name}", files, args, fragments)


def test_fuzz_cases_total():
    assert sum(c for _, c in GENERATORS) >= 1000


@pytest.fixture(scope="module")
def resumable(tmp_path_factory):
    """A completed small run with its last checkpoint; without summary.json it is resumable."""
    base = tmp_path_factory.mktemp("resumable")
    (base / "c.toml").write_text(BASE)
    proc = subprocess.run([GRAINLAB, "run", str(base / "c.toml"), "--out", str(base / "run"), "--quiet"],
                          capture_output=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    (base / "run" / ".grainlab-manifest").unlink()
    (base / "run" / "stress_dilatancy.csv").unlink()  # written with the results, like timeseries.csv
    return base / "run"


def test_fuzz_checkpoints(resumable, tmp_path):
    """Random damage to a checkpoint: flipped bits, cut, spliced, overwritten header fields, garbage."""
    rng = random.Random(f"{SEED}-checkpoint")
    good = (resumable / "checkpoint" / "state.bin").read_bytes()
    folder = tmp_path / "run"
    shutil.copytree(resumable, folder)
    (folder / "summary.json").unlink()
    (folder / "timeseries.csv").unlink()
    for i in range(100 * SCALE):
        data = bytearray(good)
        kind = rng.choice(["flips", "cut", "splice", "header", "garbage", "zeros"])
        if kind == "flips":
            for _ in range(rng.randrange(1, 20)):
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        elif kind == "cut":
            data = data[:rng.randrange(len(data))]
        elif kind == "splice":
            a, b = sorted(rng.sample(range(len(data)), 2))
            data = data[:a] + data[b:] + data[a:b]
            if bytes(data) == good:
                data[0] ^= 1
        elif kind == "header":
            pos = rng.randrange(80)
            data[pos:pos + 8] = garbage(rng, 8)
            if bytes(data) == good:
                data[pos] ^= 1
        elif kind == "garbage":
            data = bytearray(garbage(rng, rng.randrange(0, 5000)))
        else:
            data = bytearray(len(data))
        (folder / "checkpoint" / "state.bin").write_bytes(bytes(data))
        try:
            proc = subprocess.run([GRAINLAB, "resume", str(folder), "--quiet"], capture_output=True, timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            pytest.fail(f"hang: checkpoint case {i} ({kind})")
        assert_refused(proc, ["state.bin"], f"checkpoint case {i} ({kind}, seed {SEED})")
        assert sorted(os.listdir(folder)) == ["checkpoint", "config.resolved.toml", "packing.txt"], f"case {i}"


def test_fuzz_real_runs_leave_nothing_behind(tmp_path):
    """A handful of real runs refused on input, some only once the sample exists: exit 2, one line,
    and no output folder left."""
    runs = [
        (["--set", "solver.dt=1e-3"], "solver.dt"),  # above the critical step: known after preparation
        (["--set", "sample.e0=0.2", "--set", "sample.prep_friction_deg=\"auto\"", "--set", "sample.n_particles=30"],
         "sample.e0"),  # denser than frictionless compaction reaches: known after the search
        (["--set", "contact.friction_deg=nan"], "contact.friction_deg"),
        (["--set", 'sample.grading={ type = "list", file = "/dev/zero" }'], "sample.grading.file"),
        (["--set", "sample.packing=\"{dir}/c.toml\""], "sample.packing"),
    ]
    for extra, key in runs:
        folder = tmp_path / "case"
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir()
        (folder / "c.toml").write_text(BASE)
        out = folder / "out"
        argv = expand(["run", "{dir}/c.toml", "--out", str(out), "--quiet", *extra], folder)
        proc = subprocess.run([GRAINLAB, *argv], capture_output=True, timeout=300)
        assert_refused(proc, [key], f"run {extra}")
        assert sorted(os.listdir(folder)) == ["c.toml"], f"left behind by {extra}: {os.listdir(folder)}"


def test_fuzz_unwritable_output_folders(tmp_path):
    """Output folders that cannot be written: exit 1 naming the folder and the system's reason."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(BASE)
    (tmp_path / "file").write_text("x")
    for out, reason in ((tmp_path / "file" / "sub", "Not a directory"), ("/proc/grainlab-out", "No such file"),
                        ("/", "must name a folder")):
        proc = subprocess.run([GRAINLAB, "run", str(cfg), "--out", str(out), "--quiet"], capture_output=True,
                              timeout=TIMEOUT)
        stderr = proc.stderr.decode()
        assert proc.returncode in (1, 2) and len(stderr.strip().splitlines()) == 1, stderr
        assert reason in stderr, stderr
    summary_free = [p for p in os.listdir(tmp_path) if p not in ("c.toml", "file")]
    assert summary_free == []
    assert json.dumps(sorted(os.listdir(tmp_path))) == json.dumps(["c.toml", "file"])


def _forge(good, state_part_edit):
    """The checkpoint with its state bytes edited and the checksum recomputed, as a forger would."""
    import xxhash
    meta = int.from_bytes(good[64:72], "little")
    start = 80 + meta
    data = bytearray(good[:-8])
    state_part_edit(data, start, len(data))
    return bytes(data) + xxhash.xxh64(bytes(data), seed=0).intdigest().to_bytes(8, "little")


def test_fuzz_forged_checkpoints(resumable, tmp_path):
    """Checkpoints edited inside the engine state with the checksum recomputed (issue 28: a contact
    index read from such a file crashed resume). The checksum cannot catch these; the loader must:
    exit 2 naming the file, or (a forged state that is consistent) a run that ends normally or fails
    with exit 1, never a signal, a hang or a non-finite result."""
    rng = random.Random(f"{SEED}-forged")
    good = (resumable / "checkpoint" / "state.bin").read_bytes()
    folder = tmp_path / "run"
    counts = {0: 0, 1: 0, 2: 0}
    for i in range(60 * SCALE):
        kind = rng.choice(["bytes", "word", "index"])

        def edit(data, start, end):
            if kind == "bytes":
                for _ in range(rng.randrange(1, 8)):
                    data[rng.randrange(start, end)] = rng.randrange(256)
            elif kind == "word":  # a 64-bit count or value overwritten
                pos = rng.randrange(start, end - 8)
                data[pos:pos + 8] = rng.choice([b"\xff" * 8, b"\x00" * 8, (2**31).to_bytes(8, "little"),
                                                rng.randbytes(8)])
            else:  # a 32-bit index far out of range
                pos = rng.randrange(start, end - 4)
                data[pos:pos + 4] = rng.choice([4_000_000_000, 1_000_000, 2**31 - 1, 150]).to_bytes(4, "little")
        forged = _forge(good, edit)
        if folder.exists():
            shutil.rmtree(folder)
        shutil.copytree(resumable, folder)
        (folder / "summary.json").unlink()
        (folder / "timeseries.csv").unlink()
        (folder / "checkpoint" / "state.bin").write_bytes(forged)
        try:
            proc = subprocess.run([GRAINLAB, "resume", str(folder), "--quiet"], capture_output=True, timeout=60)
        except subprocess.TimeoutExpired:
            pytest.fail(f"hang: forged checkpoint case {i} ({kind})")
        case = f"forged checkpoint case {i} ({kind}, seed {SEED})"
        assert proc.returncode >= 0, f"signal {-proc.returncode}: {case}"
        assert proc.returncode in (0, 1, 2), f"exit {proc.returncode}: {case}"
        counts[proc.returncode] += 1
        if proc.returncode == 2:
            assert_refused(proc, ["state.bin"], case)
        elif proc.returncode == 0:
            text = (folder / "summary.json").read_text()
            assert "NaN" not in text and "Infinity" not in text, case
    assert counts[2] > 0  # most forgeries are refused by the loader's checks
