"""grainlab from Python: configs, runs, parameter studies and step-level scripting.

    import grainlab
    cfg = grainlab.load_config("quick-triaxial", set={"contact.beta": 0})
    result = grainlab.run(cfg, out="runs/beta0", threads=1)
    print(result.summary["phi_peak_deg"])

    sim = grainlab.Simulation("quick-triaxial", threads=1)   # a prepared sample
    sim.set_strain_rate(2, 0.5); sim.step(1000); print(sim.boundary_stress)

A run in this process goes through the same code as `grainlab run` and writes the same results
folder; with client= (a dask.distributed.Client) it is one `grainlab run` of the installed program
on a worker. docs/python.md describes every function."""
import csv
import glob
import json
import numbers
import os
import shutil
import subprocess
import sys
import tempfile
import uuid

import numpy as np

from . import _grainlab
from ._grainlab import ConfigError, SimulationError

__all__ = ["ConfigError", "SimulationError", "Config", "Result", "SweepResult", "Simulation", "load_config", "run",
           "sweep", "presets", "executable", "data_dir", "__version__"]
__version__ = _grainlab.version()

_PACKAGE = os.path.dirname(os.path.abspath(__file__))


def _prefix_paths():
    """(program, share/grainlab) of this installation: under the prefix an installed package was
    installed to, or beside the package in a build tree (build/python/grainlab)."""
    try:
        from ._prefix import PREFIX
        return os.path.join(PREFIX, "bin", "grainlab"), os.path.join(PREFIX, "share", "grainlab")
    except ImportError:
        build = os.path.dirname(os.path.dirname(_PACKAGE))
        return os.path.join(build, "grainlab"), os.path.join(build, "share", "grainlab")


_PROGRAM, _DATA = _prefix_paths()
if os.path.isdir(_DATA):
    _grainlab.set_data_dir(_DATA)


def data_dir():
    """share/grainlab of this installation (plot scripts, presets' data files), or None."""
    return _DATA if os.path.isdir(_DATA) else None


def executable():
    """The grainlab program used for client= runs and sweeps: $GRAINLAB_BIN, else the program of this
    installation (build/grainlab beside build/python, or PREFIX/bin/grainlab), else grainlab on PATH."""
    for candidate in (os.environ.get("GRAINLAB_BIN"), _PROGRAM, shutil.which("grainlab")):
        if candidate and os.access(candidate, os.X_OK):
            return os.path.abspath(candidate)
    raise RuntimeError("no grainlab program found (set GRAINLAB_BIN, or build or install grainlab)")


def presets():
    """The shipped presets: {name: description}."""
    return dict(_grainlab.presets())


# ---------------------------------------------------------------------------------------------
# Configs

def _toml_value(key, value):
    """A Python value as the TOML text of a --set value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if value != value:
            return "nan"
        if value in (float("inf"), float("-inf")):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a TOML basic string
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(key, v) for v in value) + "]"
    raise ConfigError(f"config error: --set {key}: a Python {type(value).__name__} ({value!r:.80}) is not a "
                      "config value; allowed: bool, int, float, str, list")


def _assignments(overrides):
    """set= as the CLI's --set KEY=VALUE strings: a dict {key: value}, or a list of "KEY=VALUE"."""
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        out = []
        for key, value in overrides.items():
            if not isinstance(key, str):
                raise ConfigError(f"config error: --set key {key!r:.80}: not a string; allowed: dotted keys such as "
                                  "\"contact.beta\"")
            out.append(f"{key}={_toml_value(key, value)}")
        return out
    if isinstance(overrides, str):
        return [overrides]
    return [str(s) for s in overrides]


class Config:
    """A validated config: its source ("preset:NAME", a file path or "<dict>"), the --set overrides, and
    the resolved values. Made by load_config()."""

    def __init__(self, native, source_object):
        self._native = native
        self._source_object = source_object

    @property
    def source(self):
        return self._native.source

    @property
    def overrides(self):
        return list(self._native.overrides)

    @property
    def output_dir(self):
        return self._native.output_dir

    def toml(self):
        """The config as given, overrides applied (TOML text)."""
        return self._native.toml()

    def resolved_toml(self):
        """Every key with its default filled in, as `grainlab check` prints it."""
        return self._native.resolved_toml()

    def to_dict(self):
        """The resolved config as a nested dict."""
        import tomllib
        return tomllib.loads(self.resolved_toml())

    def with_overrides(self, set):
        """This config with more overrides applied (validated again)."""
        return _load(self._source_object, self.overrides + _assignments(set))

    def _program_args(self, scratch):
        """The CONFIG argument and --set options that give this config to the grainlab program. A
        config given as a dict is written as a TOML file into `scratch`."""
        if self.source == "<dict>":
            path = os.path.join(scratch, "config.toml")
            with open(path, "w") as f:
                f.write(self.toml())
            return path, []
        sets = []
        for s in self.overrides:
            sets += ["--set", s]
        return self.source, sets

    def __repr__(self):
        extra = f", set={self.overrides}" if self.overrides else ""
        return f"grainlab.Config({self.source!r}{extra})"


def _load(source, assignments):
    if isinstance(source, str) and not source.startswith("preset:") and _grainlab.is_preset(source) \
            and not os.path.exists(source):
        source = "preset:" + source
    return Config(_grainlab.load_config(source, assignments), source)


def load_config(source, set=None):
    """Loads and validates a config, with the CLI's rules and error messages.

    source: a preset ("preset:quick-triaxial" or "quick-triaxial"), a TOML file path, or a dict nested
    like the TOML file (its relative file names are resolved against the current folder).
    set: overrides applied exactly as `--set`: {"contact.beta": 0, ...} or ["contact.beta=0", ...].
    Raises ConfigError (a ValueError) with the line the CLI prints after "grainlab: "."""
    if isinstance(source, Config):
        return source.with_overrides(set) if set else source
    return _load(source, _assignments(set))


def _config(config, set=None):
    return load_config(config, set=set)


# ---------------------------------------------------------------------------------------------
# Results

def _read_table(path):
    """A CSV file with a header as a numpy structured array: a column of integers is int64, any other
    float64, an empty field (a value that could not be measured) NaN; text columns stay text."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return np.zeros(0)
    header, body = rows[0], rows[1:]
    columns, dtypes = [], []
    for k, name in enumerate(header):
        raw = [r[k] if k < len(r) else "" for r in body]
        try:
            values = [int(v) for v in raw]
            dtype = np.int64
        except ValueError:
            try:
                values = [float(v) if v != "" else np.nan for v in raw]
                dtype = np.float64
            except ValueError:
                values = raw
                dtype = "U" + str(max([1] + [len(v) for v in raw]))
        columns.append(values)
        dtypes.append((name, dtype))
    table = np.zeros(len(body), dtype=dtypes)
    for (name, _), values in zip(dtypes, columns):
        table[name] = values
    return table


class Result:
    """The results folder of one run (README "Results folder")."""

    def __init__(self, folder):
        self.folder = os.path.abspath(folder)
        path = os.path.join(self.folder, "summary.json")
        with open(path) as f:
            self.summary = json.load(f)
        series = os.path.join(self.folder, "timeseries.csv")
        self._timeseries = None if not os.path.exists(series) else series

    @property
    def status(self):
        return self.summary.get("status")

    @property
    def timeseries(self):
        """The time series (timeseries.csv) as a numpy structured array; NaN where a value could not be
        measured. None when the run wrote none (it failed)."""
        if self._timeseries is None:
            return None
        if not hasattr(self, "_table"):
            self._table = _read_table(self._timeseries)
        return self._table

    def dataframe(self):
        """The time series as a pandas DataFrame (needs pandas: Debian python3-pandas)."""
        import pandas
        return pandas.DataFrame(self.timeseries)

    @property
    def plots(self):
        return sorted(glob.glob(os.path.join(self.folder, "*.png")))

    @property
    def vtk(self):
        return sorted(glob.glob(os.path.join(self.folder, "vtk", "*.vt*")))

    def __repr__(self):
        return f"grainlab.Result({self.folder!r}, status={self.status!r})"


# The most OpenMP threads any grainlab command accepts (solver.threads, --threads).
MAX_THREADS = 1024


def _threads(threads, name="threads"):
    """threads as the program takes it: None for the config's solver.threads, else 1..MAX_THREADS.
    0, negative, bool and non-integer values are refused (they used to mean "not given")."""
    if threads is None:
        return 0
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or not 1 <= threads <= MAX_THREADS:
        raise ConfigError(f"{name} = {threads!r:.80}; allowed: None (the config's solver.threads) or an integer "
                          f"in [1, {MAX_THREADS}]")
    return int(threads)


def _folder(out, name="out"):
    """A results folder as given (str or os.PathLike), or None; an empty name is refused (it used to
    mean "not given")."""
    if out is None:
        return None
    path = os.fspath(out)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if path == "":
        raise ConfigError(f"{name} = '': must be a non-empty folder name (or None for the config's output.dir)")
    return path


def run(config, out=None, threads=None, progress=None, client=None, set=None, quiet=True):
    """Runs a test and returns its Result.

    config: a Config, or what load_config() accepts (set= applies overrides). out: the results folder
    (default output.dir); a folder of earlier results is replaced only once the run completes.
    threads: OpenMP threads (default solver.threads). progress(phase, fraction, steps): called as the
    program reports progress (every 1000-2000 steps), with the GIL held; an exception it raises stops
    the run. Ctrl-C stops the run between steps with KeyboardInterrupt; its summary.json then says
    "interrupted" (and a checkpoint, if any, resumes with `grainlab resume`).
    client: a dask.distributed.Client: the run is one `grainlab run` of the installed program on a
    worker, its folder sent back to `out` (progress is not reported)."""
    cfg = _config(config, set)
    out = _folder(out)
    threads = _threads(threads)
    if client is not None:
        return _run_on_client(cfg, out, threads, client)
    folder = _grainlab.run(cfg._native, "" if out is None else out, threads, bool(quiet), progress)
    return Result(folder)


def _dask_runner():
    """tools/dask_runner.py of this installation (the program's own Dask code) as a module."""
    import importlib.util
    path = os.path.join(_DATA, "tools", "dask_runner.py")
    if not os.path.exists(path):
        raise RuntimeError(f"{path} not found: the Dask runner is installed with the grainlab program")
    spec = importlib.util.spec_from_file_location("grainlab_dask_runner", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _run_on_client(cfg, out, threads, client):
    import cloudpickle
    runner = _dask_runner()
    # Workers need run_case but not this file: its module travels by value (as in the program's sweeps).
    cloudpickle.register_pickle_by_value(runner)
    out = os.path.abspath(os.fspath(out) if out is not None else cfg.output_dir)
    with tempfile.TemporaryDirectory(prefix="grainlab-") as scratch:
        source, sets = cfg._program_args(scratch)
        config_text = None
        if not source.startswith("preset:"):
            with open(source) as f:
                config_text = f.read()
        job = {"executable": executable(), "config": source, "config_text": config_text,
               "name": os.path.basename(out) or "run", "sets": sets[1::2], "threads": int(threads or 0),
               "out": out, "mode": "return", "token": uuid.uuid4().hex}
        future = client.submit(runner.run_case, job, key=f"grainlab-run-{job['token'][:8]}", pure=False,
                               retries=runner.TASK_RETRIES)
        result = future.result()
    if result["files"] is not None:
        os.makedirs(os.path.dirname(out), exist_ok=True)
        runner._unpack(result["files"], out)
    if result["exit_code"] == 2:
        raise ConfigError(_error_line(result["log"]))
    if result["exit_code"] != 0 and not os.path.exists(os.path.join(out, "summary.json")):
        raise SimulationError(f"run on {result['worker']} failed (exit {result['exit_code']}): "
                              f"{_error_line(result['log'])}")
    return Result(out)


def _error_line(log):
    """The program's one-line error (its last line starting "grainlab: "), without that prefix."""
    lines = [line for line in log.splitlines() if line.startswith("grainlab: ")]
    return lines[-1][len("grainlab: "):] if lines else log.strip()[-300:]


class SweepResult:
    """The folder of a sweep: its table (sweep.csv) and each case's Result."""

    def __init__(self, folder):
        self.folder = os.path.abspath(folder)
        self.table = _read_table(os.path.join(self.folder, "sweep.csv"))

    @property
    def stats(self):
        """The rows of sweep-stats.csv (a sweep with seeds >= 2: per case of the other keys, each
        quantity's _mean, _std, _min, _max and _n over its seeds; NaN where not measured) as a
        structured array, else None."""
        path = os.path.join(self.folder, "sweep-stats.csv")
        return _read_table(path) if os.path.exists(path) else None

    @property
    def cases(self):
        """{case name: Result} of the cases that left a summary."""
        out = {}
        for d in sorted(os.listdir(self.folder)):
            if os.path.exists(os.path.join(self.folder, d, "summary.json")):
                out[d] = Result(os.path.join(self.folder, d))
        return out

    @property
    def plots(self):
        return sorted(glob.glob(os.path.join(self.folder, "*.png")))

    def __repr__(self):
        return f"grainlab.SweepResult({self.folder!r}, {len(self.table)} cases)"


def sweep(config, vary=None, out=None, client=None, set=None, jobs=None, threads=None, quiet=True, seeds=None):
    """A grid of runs and their comparison table: `grainlab sweep` of the installed program.

    vary: {"contact.beta": [0, 0.15], ...} (a grid over every key). seeds: N replicate seeds per
    case (sample.seed, +1, ..., +N-1; `--seeds`), whose statistics are SweepResult.stats. client: a
    dask.distributed.Client whose scheduler runs the cases (`--scheduler`), else local processes,
    `jobs` at a time. Returns a SweepResult; raises ConfigError for a refused config or vary."""
    cfg = _config(config, set)
    if seeds is not None and (isinstance(seeds, bool) or not isinstance(seeds, numbers.Integral)
                              or not 1 <= seeds <= 1000):
        raise ConfigError(f"seeds = {seeds!r:.80}; allowed: None or an integer in [1, 1000]")
    out = _folder(out)
    threads = _threads(threads)
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, numbers.Integral) or not 1 <= jobs <= 4096):
        raise ConfigError(f"jobs = {jobs!r:.80}; allowed: None or an integer in [1, 4096]")
    if vary is None and seeds is not None and seeds >= 2:
        vary = {}
    elif not isinstance(vary, dict) or not vary:
        raise ConfigError(f"sweep: vary = {vary!r:.80}; allowed: a non-empty dict {{key: [values]}}, or None "
                          "with seeds >= 2")
    if out is not None and os.fspath(out) in ("", b""):
        # The program would take an empty --out for "not given" (runs/sweep): refused.
        raise ConfigError("sweep: out = '': empty; give a folder, or None for runs/sweep")
    with tempfile.TemporaryDirectory(prefix="grainlab-") as scratch:
        source, sets = cfg._program_args(scratch)
        argv = [executable(), "sweep", source, *sets]
        for key, values in vary.items():
            if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                values = [values]
            argv += ["--vary", f"{key}=" + ",".join(_toml_value(key, v) for v in values)]
        if out is not None:
            argv += ["--out", os.fspath(out)]
        if jobs:
            argv += ["--jobs", str(int(jobs))]
        if threads:
            argv += ["--threads", str(int(threads))]
        if seeds is not None:
            argv += ["--seeds", str(int(seeds))]
        if client is not None:
            argv += ["--scheduler", client.scheduler.address]
        if quiet:
            argv.append("--quiet")
        proc = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace",
                              stdin=subprocess.DEVNULL)
    if proc.returncode == 2:
        raise ConfigError(_error_line(proc.stderr))
    folder = os.fspath(out) if out is not None else os.path.join("runs", "sweep")
    if not os.path.exists(os.path.join(folder, "sweep.csv")):
        raise SimulationError(f"sweep failed (exit {proc.returncode}): {_error_line(proc.stderr)}")
    return SweepResult(folder)


# ---------------------------------------------------------------------------------------------
# Step-level scripting

class Simulation(_grainlab.Simulation):
    """A prepared sample (the laboratory's preparation of the config: placement, compaction to e0,
    equilibrium at the confining pressure) to step and drive from Python.

    positions, velocities, angular_velocities, forces, orientations (x, y, z, w), radii, semi_axes,
    masses, ids are numpy views of the engine's arrays, without copies: they see every step and stay
    valid as long as the arrays are not reallocated, which nothing in this API does (the view keeps
    this Simulation alive). positions and velocities are writeable; the others are read-only.
    contacts() returns a copy. Strains are engineering strains since reset_reference() (the end of
    preparation at first), compression positive; stresses in Pa, compression positive."""

    def __init__(self, config, set=None, threads=None, progress=None):
        cfg = _config(config, set)
        self.config = cfg
        super().__init__(cfg._native, _threads(threads), progress)

    @property
    def p(self):
        """Mean boundary stress [Pa]."""
        return float(np.mean(self.boundary_stress))

    @property
    def q(self):
        """Deviator stress sigma_z - (sigma_x + sigma_y)/2 of the boundary [Pa] (axial z)."""
        s = self.boundary_stress
        return float(s[2] - 0.5 * (s[0] + s[1]))

    def inertial_rate(self, inertial_number=1e-3):
        """The strain rate [1/s] whose inertial number I = rate d50 sqrt(rho/p) at the current p is
        `inertial_number` (the CLI's "auto" rate aims just under 1e-3)."""
        return inertial_number / (self.d50 * np.sqrt(self.density / self.p))

    def state(self):
        """The measurements of the current step as a dict of plain numbers."""
        s = self.boundary_stress
        e = self.strain
        return {"step": self.step_count, "time": self.time, "eps_x": float(e[0]), "eps_y": float(e[1]),
                "eps_z": float(e[2]), "eps_v": self.volumetric_strain, "sigma_x": float(s[0]),
                "sigma_y": float(s[1]), "sigma_z": float(s[2]), "p": self.p, "q": self.q, "e": self.void_ratio,
                "coordination": self.coordination, "unbalanced": self.unbalanced}
