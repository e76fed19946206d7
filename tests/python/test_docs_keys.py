"""The reference docs (docs/interface.md, docs/laboratory.md, docs/physics.md) against the program, so
that neither can drift from the other:

- the configuration keys listed in docs/interface.md are exactly the keys src/io/config.cpp reads;
- every default written there is what `grainlab check` prints, and a key written as unset is not
  printed;
- every option of every subcommand's --help is documented in that subcommand's section;
- the presets table lists exactly what `grainlab presets` lists;
- the time-series columns and summary keys of docs/laboratory.md are what a short run writes (the
  columns of the cell, simple-shear and true-triaxial tests from src/io/results.cpp);
- every link to a heading of these pages resolves.
"""
import json
import os
import re
import subprocess
import tomllib

import pytest

from conftest import DATA, GRAINLAB

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
DOCS = os.path.join(ROOT, "docs")
SECTIONS = ("sample", "contact", "test", "solver", "output")


def read(*parts):
    with open(os.path.join(ROOT, *parts), encoding="utf-8") as f:
        return f.read()


def section(text, heading):
    """The text under a Markdown heading that starts with `heading`, up to the next heading of the same
    or a higher level."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("#") and line.lstrip("#").strip().startswith(heading):
            level = len(line) - len(line.lstrip("#"))
            body = []
            for nxt in lines[i + 1:]:
                if nxt.startswith("#") and len(nxt) - len(nxt.lstrip("#")) <= level:
                    break
                body.append(nxt)
            return "\n".join(body)
    raise AssertionError(f"no heading {heading!r}")


def table_rows(text):
    """Cells of the Markdown table rows in `text` (header and separator rows included)."""
    return [[c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line.strip()[1:-1])]
            for line in text.splitlines() if line.strip().startswith("|")]


def documented_keys():
    """docs/interface.md: config key -> its default cell."""
    keys = {}
    for cells in table_rows(section(read("docs", "interface.md"), "Configuration")):
        m = re.fullmatch(r"`((?:%s)\.[a-z0-9_.]+)`" % "|".join(SECTIONS), cells[0])
        if m:
            assert m.group(1) not in keys, f"{m.group(1)} documented twice"
            assert len(cells) == 5, f"row of {m.group(1)}: expected key | type | default | allowed | meaning"
            keys[m.group(1)] = cells[2]
    return keys


def source_keys():
    """Every key src/io/config.cpp reads: section getters, and the keys of the inline tables."""
    src = read("src", "io", "config.cpp")
    variables = dict(re.findall(r'Section (\w+)\(root, "(\w+)"\)', src))
    assert set(variables.values()) == set(SECTIONS), variables
    keys = {f"{variables[v]}.{k}" for v, k in
            re.findall(r'\b(\w+)\.(?:number|integer|boolean|string|raw)\("(\w+)"', src) if v in variables}

    def body(start, end):
        i = src.index(start)
        return src[i:src.index(end, i)]

    grading = set(re.findall(r'get\("(\w+)"\)', body("lab::GradingConfig parseGrading", "\n}\n")))
    shape = set(re.findall(r'name != "(\w+)"', body("lab::ShapeConfig parseShape", "\n}\n")))
    sphericity = set(re.findall(r'name != "(\w+)"', body("if (sph) {", "c.contact.sphericity = sc;")))
    for name, sub in (("grading", grading), ("shape", shape), ("sphericity", sphericity)):
        assert sub, f"no keys of {name} found in config.cpp: the test's patterns need updating"
    keys |= {f"sample.grading.{k}" for k in grading}
    keys |= {f"sample.shape.{k}" for k in shape}
    keys |= {f"contact.sphericity.{k}" for k in sphericity}
    return keys


def flatten(table, prefix=""):
    out = {}
    for k, v in table.items():
        if isinstance(v, dict):
            out.update(flatten(v, prefix + k + "."))
        else:
            out[prefix + k] = v
    return out


def test_documented_keys_are_the_parsers_keys():
    doc, src = set(documented_keys()), source_keys()
    assert not src - doc, f"accepted by config.cpp but not in docs/interface.md: {sorted(src - doc)}"
    assert not doc - src, f"in docs/interface.md but not read by config.cpp: {sorted(doc - src)}"


def test_documented_defaults_are_what_check_prints(grainlab, tmp_path):
    sphericity = os.path.abspath(os.path.join(ROOT, "presets", "data", "sphericity-synthetic.csv"))
    configs = {
        "defaults": "",
        "rolling": '[contact]\nmodel = "rolling-linear"\n',
        "sphericity": f'[contact]\nmodel = "rolling-linear"\nsphericity = {{ file = "{sphericity}", k = -4.0 }}\n',
        # Keys printed only where they apply (config.resolved.toml and check write exactly those).
        "growth": '[sample]\nmethod = "growth"\n',
        "ellipsoid-a": '[sample]\nmethod = "growth"\nshape = { type = "ellipsoid", elongation = 0.7 }\n',
        "ellipsoid-b": '[sample]\nmethod = "growth"\nshape = { type = "ellipsoid", flatness = 0.8 }\n',
        "true-triaxial": '[test]\ntype = "true-triaxial"\n',
        "loops": '[test]\nunload_reload_at = [0.05]\n',
        "simple-shear": '[test]\ntype = "simple-shear"\nboundary = "periodic"\n',
        "oedometer": '[test]\ntype = "oedometer"\n',
        "cyclic-triaxial": '[test]\ntype = "cyclic-triaxial"\n',
        "cyclic-simple-shear": '[test]\ntype = "cyclic-simple-shear"\nboundary = "periodic"\n',
        "dt": '[solver]\ndt = 1e-7\n',
        "hertz-mindlin": '[contact]\nmodel = "hertz-mindlin"\n',
        "deposition": '[sample]\nmethod = "deposition"\n',
        "under-compaction": '[sample]\nmethod = "under-compaction"\n',
        "membrane": '[sample]\nn_particles = 3000\n[test]\nboundary = "membrane"\nplaten_friction_deg = 0.0\n',
    }
    printed = {}
    for name, text in configs.items():
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        printed[name] = flatten(tomllib.loads(grainlab("check", str(path), check=0).stdout))
    resolved, seen = {}, {}
    for name in configs:
        for k, v in printed[name].items():
            resolved.setdefault(k, v)
            seen.setdefault(k, []).append(v)
    problems = []
    for key, cell in documented_keys().items():
        if cell == "—":
            if key in printed["defaults"]:
                problems.append(f"{key}: documented as unset, check prints {printed['defaults'][key]!r}")
            continue
        literal = re.fullmatch(r"`(.+)`", cell)
        if not literal:
            continue  # a table of keys whose own rows carry the defaults
        value = tomllib.loads("v = " + literal.group(1))["v"]
        if key not in resolved:
            problems.append(f"{key}: documented default {literal.group(1)}, not printed by check")
        elif value not in seen[key]:
            problems.append(f"{key}: documented default {literal.group(1)}, check prints {resolved[key]!r}")
    documented = documented_keys()
    for key in printed["defaults"]:
        if key not in documented:
            problems.append(f"{key}: printed by check, not documented")
    assert not problems, "\n".join(problems)


SUBCOMMANDS = ("run", "check", "resume", "presets", "sweep", "calibrate", "analyse", "bench")


def test_every_option_of_every_command_is_documented(grainlab):
    doc = section(read("docs", "interface.md"), "Commands")
    top = grainlab("--help", check=0).stdout
    listed = set(re.findall(r"^  ([a-z]+) {2,}", top.split("Subcommands:")[1], re.M))
    assert listed == set(SUBCOMMANDS), f"subcommands in --help: {sorted(listed)}"
    missing = []
    for sub in SUBCOMMANDS:
        text = section(doc, f"`grainlab {sub}")
        options = set(re.findall(r"(--[a-z][a-z-]*)", grainlab(sub, "--help", check=0).stdout)) - {"--help"}
        missing += [f"grainlab {sub} {o}" for o in sorted(options) if f"`{o}" not in text]
    assert not missing, f"options not documented in their command's section: {missing}"


def test_presets_table_lists_the_shipped_presets(grainlab):
    shipped = {line.split()[0] for line in grainlab("presets", check=0).stdout.splitlines() if line.strip()}
    rows = table_rows(section(read("docs", "interface.md"), "Presets"))
    documented = {m.group(1) for cells in rows if (m := re.fullmatch(r"`([a-z0-9-]+)`", cells[0]))}
    assert documented == shipped
    lab = table_rows(section(read("docs", "laboratory.md"), "5. Reference set-ups and presets"))
    assert {m.group(1) for cells in lab if (m := re.fullmatch(r"`([a-z0-9-]+)`", cells[0]))} == shipped


def names_in(cell):
    """Backticked names of a table cell, `x_1..3` expanded, comma lists inside one pair of backticks split."""
    names = []
    for group in re.findall(r"`([^`]+)`", cell):
        for name in (n.strip() for n in group.split(",")):
            m = re.fullmatch(r"(\w+)_1\.\.3", name)
            names += [f"{m.group(1)}_{k}" for k in (1, 2, 3)] if m else [name]
    return names


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """A short triaxial test in a wall box: 300 spheres, 0.3 % axial strain, no plots or snapshots."""
    out = tmp_path_factory.mktemp("docs") / "run"
    proc = subprocess.run([GRAINLAB, "run", os.path.join(DATA, "small-triaxial.toml"), "--out", str(out), "--quiet",
                           "--threads", "1", "--set", "test.final_axial_strain=0.003",
                           "--set", "output.vtk_every_strain=0", "--set", "output.checkpoint_every=0"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return out


def test_timeseries_columns_are_documented_in_order(short_run):
    header = (short_run / "timeseries.csv").read_text().splitlines()[0].split(",")
    # The columns of the other tests, where results.cpp inserts them: before energy_residual.
    src = read("src", "io", "results.cpp")
    extra = dict(re.findall(r'if \(columns\.(\w+)\) s \+= ",([A-Za-z0-9_,]+)";', src))
    assert set(extra) == {"periodic", "simpleShear", "trueTriaxial", "loops", "undrained", "cyclic", "reversing",
                          "stressPath", "cyclicShear", "gravity"}, extra
    i = header.index("energy_residual")
    # The unload-reload column and the undrained, cyclic and reversing tests' columns come last,
    # after the micromechanics columns.
    expected = (header[:i] + [n for k in ("periodic", "simpleShear", "trueTriaxial") for n in extra[k].split(",")]
                + header[i:] + [n for k in ("loops", "undrained", "cyclic", "reversing", "stressPath", "cyclicShear", "gravity") for n in extra[k].split(",")])
    rows = table_rows(section(read("docs", "laboratory.md"), "3.2 Time series columns"))
    documented = [n for cells in rows[2:] for n in names_in(cells[0])]
    assert documented == expected


SUMMARY_ONLY_SOMETIMES = {
    "mu_r_mean", "mu_r_min", "mu_r_max",   # rolling-linear runs
    "G_MPa", "final_shear_strain", "gamma0",  # simple shear
    "growth_curve",                        # ellipsoid shape growth
    "deposition",                          # sample.method = "deposition"
    "under_compaction",                    # sample.method = "under-compaction"
    "membrane",                            # test.boundary = "membrane"
    "rate_factor_min",                     # test.rate_follows_pressure = true
    "Eur_at_eps1",                         # runs with unload-reload loops
    "error",                               # failed runs
    # undrained tests
    "u_max", "u_min", "cavitation_pressure", "cavitated", "cavitations", "cavitation_strain",
    "p_min", "q_at_phase_transformation", "eps1_at_phase_transformation", "liquefied", "volume_drift_max",
    # oedometer
    "K0", "K0_unloading", "Cc", "Cs", "sigma_v_max", "oedometer_method",
    # cyclic triaxial
    "n_cycles_to_liquefaction", "ru_max", "cycles", "double_amplitude_strain_max", "csr", "liquefaction_criterion",
    # cyclic simple shear
    "shear_strain_amplitudes", "G_secant_MPa", "G_over_Gmax", "damping_ratio", "Gmax_MPa", "cycles_per_amplitude",
    "G_method", "ru_max_per_amplitude", "liquefied_at_amplitude",
    # stress path
    "path_points", "path_source", "path_completed", "path_s_reached", "path_stress_deviation_max", "path_method",
}


def test_summary_keys_are_documented(short_run):
    summary = json.loads((short_run / "summary.json").read_text())
    rows = table_rows(section(read("docs", "laboratory.md"), "3.4 Summary"))
    documented = {}
    for cells in rows[2:]:
        for name in names_in(cells[0]):
            documented[name] = cells[1]
    assert not set(summary) - set(documented), f"written but not documented: {sorted(set(summary) - set(documented))}"
    stale = set(documented) - set(summary) - SUMMARY_ONLY_SOMETIMES
    assert not stale, f"documented but not written by a triaxial run: {sorted(stale)}"
    for nested in ("grading", "isotropic_state"):
        assert set(names_in(documented[nested])) == set(summary[nested]), nested


def slug(heading):
    """GitHub's anchor of a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


@pytest.mark.parametrize("page", ["physics.md", "laboratory.md", "interface.md"])
def test_links_to_headings_resolve(page):
    text = read("docs", page)
    broken = []
    for target, anchor in re.findall(r"\]\(([\w./-]*?)#([\w-]+)\)", text):
        path = os.path.join(DOCS, target) if target else os.path.join(DOCS, page)
        if not os.path.exists(path):
            broken.append(f"{target}#{anchor}: no such file")
            continue
        with open(path, encoding="utf-8") as f:
            anchors = {slug(line.lstrip("#")) for line in f if line.startswith("#")}
        if anchor not in anchors:
            broken.append(f"{target or page}#{anchor}")
    for target in re.findall(r"\]\(([\w./-]+\.md)\)", text):
        if not os.path.exists(os.path.join(DOCS, target)):
            broken.append(f"{target}: no such file")
    assert not broken, broken


def tracked_text_files():
    out = subprocess.run(["git", "-C", ROOT, "ls-files", "src", "tests", "tools", "python", "bench", "scripts", "docs",
                          "README.md", "examples", "presets"], capture_output=True, text=True)
    if out.returncode != 0:
        pytest.skip("not a git checkout")
    suffixes = (".cpp", ".hpp", ".py", ".md", ".toml", ".sh", ".txt")
    return [p for p in out.stdout.split() if p.endswith(suffixes)]


def test_citations_are_to_the_repository_docs_and_their_sections_exist():
    # The project's docs stand alone: no citation of the specification files outside the repository
    # (PHYSICS.md, LAB.md, INTERFACE.md, numbered differently), and every "docs/<page>.md §N" cited
    # names a numbered heading of that page.
    spec = re.compile(r"(?<![\w/])(PHYSICS|LAB|INTERFACE)\.md")
    cited = re.compile(r"docs/(physics|laboratory|interface)\.md((?: §\d+(?:\.\d+)?(?:–\d+)?,?)+)")
    headings = {}
    for page in ("physics", "laboratory", "interface"):
        nums = set()
        for line in read("docs", page + ".md").splitlines():
            m = re.match(r"#+ (\d+(?:\.\d+)?)\.? ", line)
            if m:
                nums.add(m.group(1))
        headings[page] = nums
    bad, missing = [], []
    this = os.path.relpath(__file__, ROOT)
    for path in tracked_text_files():
        if os.path.normpath(path) == os.path.normpath(this):
            continue
        try:
            text = read(path)
        except (UnicodeDecodeError, FileNotFoundError):
            continue
        for n, line in enumerate(text.splitlines(), 1):
            if spec.search(line):
                bad.append(f"{path}:{n}: {line.strip()[:100]}")
            for m in cited.finditer(line):
                for sec in re.findall(r"§(\d+(?:\.\d+)?)", m.group(2)):
                    if sec not in headings[m.group(1)]:
                        missing.append(f"{path}:{n}: docs/{m.group(1)}.md §{sec}")
    assert not bad, "citations of the specification outside the repository:\n" + "\n".join(bad)
    assert not missing, "cited sections that the page does not have:\n" + "\n".join(missing)
