"""Progress in logs (issue 25 §4): when stderr is not a terminal, a run prints a plain progress line
every GRAINLAB_PROGRESS_SECONDS seconds of a phase (60 by default), none with --quiet, and a bad
value of the variable is refused before anything is written."""
import os
import re
import subprocess

from conftest import GRAINLAB, TINY_CONFIG


def run(tmp_path, env_value, *extra):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TINY_CONFIG)
    env = dict(os.environ)
    env.pop("GRAINLAB_PROGRESS_SECONDS", None)
    if env_value is not None:
        env["GRAINLAB_PROGRESS_SECONDS"] = env_value
    out = tmp_path / "out"
    proc = subprocess.run([GRAINLAB, "run", str(cfg), "--out", str(out), *extra], capture_output=True, text=True,
                          env=env, timeout=300)
    return proc, out


LINE = re.compile(r"^grainlab: progress: (.+?): ([0-9.]+) %, (\d+) steps, \d+ steps/s, elapsed \d+ s, ETA .+$")


def test_log_lines_when_stderr_is_not_a_terminal(tmp_path):
    proc, _ = run(tmp_path, "0")
    assert proc.returncode == 0, proc.stderr
    lines = [LINE.match(l) for l in proc.stderr.splitlines() if l.startswith("grainlab: progress:")]
    assert lines and all(lines), proc.stderr
    phases = [m.group(1) for m in lines]
    assert "triaxial shearing" in phases, phases
    shear = [float(m.group(2)) for m in lines if m.group(1) == "triaxial shearing"]
    assert shear == sorted(shear) and 0.0 < shear[-1] < 100.0
    assert "\r" not in proc.stderr and "\033[" not in proc.stderr  # no terminal control in a log


def test_no_lines_in_a_short_run_by_default_or_with_quiet(tmp_path):
    proc, _ = run(tmp_path, None)
    assert proc.returncode == 0, proc.stderr
    assert "grainlab: progress:" not in proc.stderr  # a one-second run is under the 60 s default
    (tmp_path / "q").mkdir()
    proc, _ = run(tmp_path / "q", "0", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert "progress" not in proc.stderr


def test_bad_interval_is_refused_before_anything_is_written(tmp_path):
    for bad in ["abc", "-1", "nan", "1e9", "5s"]:
        proc, out = run(tmp_path, bad)
        assert proc.returncode == 2, (bad, proc.stderr)
        assert "GRAINLAB_PROGRESS_SECONDS" in proc.stderr and f'"{bad}"' in proc.stderr, proc.stderr
        assert "[0, 1e6]" in proc.stderr
        assert not out.exists(), bad
