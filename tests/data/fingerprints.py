#!/usr/bin/env python3
"""Fingerprints of shortened runs of every preset and of the tests and laws no preset uses.

A behaviour-preserving change to the engine or the laboratory (issue 25 part 1, issue 24's seam)
must leave every run's timeseries.csv byte-identical. This script runs each case on one thread and
records the SHA-256 of its timeseries.csv in fingerprints.json; tests/python/test_fingerprints.py
runs the same cases and compares.

This is a change detector, not validation: it says *that* the numbers changed, not whether they
are right. When a commit changes results on purpose (a physics fix, a new default), regenerate the
file and say in the commit message which cases changed and why:

    /usr/bin/python3 tests/data/fingerprints.py --write [--bin build/grainlab]

Without --write it compares and prints one line per case. The hashes hold for this toolchain
(Debian 12, g++ 12, x86-64 without -march); another compiler or libm may change the last bits.
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
FILE = os.path.join(HERE, "fingerprints.json")
SHORT = ["--set", "sample.n_particles=300", "--set", "test.final_axial_strain=0.01", "--set", "test.probe_strain=0"]

# name -> (config, --set arguments). Each case runs in about 3-12 s on one thread of the 2-core VM.
CASES = {
    "quick-triaxial": ("preset:quick-triaxial", SHORT),
    "w-base": ("preset:w-base", SHORT + ["--set", "sample.e0=0.72"]),  # 300 spheres pack no denser than 0.696
    "karlsruhe-calibrated": ("preset:karlsruhe-calibrated", SHORT),
    "karlsruhe-dense-x10": ("preset:karlsruhe-dense-x10", SHORT),
    "karlsruhe-dense-paper": ("preset:karlsruhe-dense-paper", SHORT),
    "rorato-sphericity": ("preset:rorato-sphericity", SHORT),
    "periodic-triaxial": ("preset:periodic-triaxial", SHORT),
    "csl-dense": ("preset:csl-dense", SHORT),
    "csl-loose": ("preset:csl-loose", SHORT),
    "ouadfel-spheroids": ("preset:ouadfel-spheroids",
                          ["--set", "sample.n_particles=125", "--set", "test.final_axial_strain=0.01"]),
    "stress-path-b": ("preset:stress-path-b", ["--set", "sample.n_particles=300", "--set", "test.probe_strain=0"]),
    "stress-path-constant-p": ("preset:stress-path-constant-p",
                               ["--set", "sample.n_particles=300", "--set", "test.probe_strain=0"]),
    # 2700 grains: about the smallest membrane sample of this grading preflight allows (8 d50 across).
    "membrane-triaxial": ("preset:membrane-triaxial",
                          ["--set", "sample.n_particles=2700", "--set", "test.final_axial_strain=0.004",
                           "--set", "test.probe_strain=0"]),
    # Tests, laws and preparations no preset runs.
    "undrained-triaxial": ("preset:quick-triaxial", SHORT + ["--set", 'test.drainage="undrained"']),
    "oedometer": ("preset:quick-triaxial",
                  SHORT + ["--set", 'test.type="oedometer"', "--set", "test.max_axial_stress=3e5",
                           "--set", "test.unload_axial_stress=2e5"]),
    "simple-shear": ("preset:periodic-triaxial",
                     SHORT + ["--set", 'test.type="simple-shear"', "--set", "test.final_shear_strain=0.01"]),
    "hertz-mindlin": ("preset:quick-triaxial", SHORT + ["--set", 'contact.model="hertz-mindlin"']),
    "gravity": ("preset:quick-triaxial", SHORT + ["--set", "sample.gravity=[0, 0, -98.1]"]),
    "deposition": ("preset:quick-triaxial", ["--set", "sample.n_particles=100", "--set", 'sample.method="deposition"',
                                             "--set", "test.final_axial_strain=0.005", "--set", "test.probe_strain=0"]),
    "under-compaction": ("preset:quick-triaxial",
                         ["--set", "sample.n_particles=100", "--set", 'sample.method="under-compaction"',
                          "--set", "test.final_axial_strain=0.005", "--set", "test.probe_strain=0"]),
}


def run_case(binary, name, workdir, simd=None):
    """SHA-256 of the case's timeseries.csv; simd: a GRAINLAB_SIMD value (None: the environment's)."""
    config, sets = CASES[name]
    out = os.path.join(workdir, name if simd is None else f"{name}-{simd}")
    env = dict(os.environ)
    if simd is not None:
        env["GRAINLAB_SIMD"] = simd
    # No plots: they take 5 of a case's 7 s and do not enter timeseries.csv.
    proc = subprocess.run([binary, "run", config, "--out", out, "--quiet", "--threads", "1", *sets,
                           "--set", "output.plots=false"],
                          capture_output=True, text=True, timeout=900, env=env)
    if proc.returncode != 0:
        raise RuntimeError(f"{name}: grainlab exited {proc.returncode}: {proc.stderr.strip()}")
    with open(os.path.join(out, "timeseries.csv"), "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def main():
    default_bin = os.path.join(HERE, "..", "..", "build", "grainlab")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.environ.get("GRAINLAB_BIN", default_bin))
    ap.add_argument("--write", action="store_true", help="record the hashes in fingerprints.json")
    ap.add_argument("cases", nargs="*", help="only these cases (default: all)")
    args = ap.parse_args()
    names = args.cases or list(CASES)
    known = json.load(open(FILE)) if os.path.exists(FILE) else {}
    changed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            t = time.time()
            digest = run_case(args.bin, name, tmp)
            same = known.get(name) == digest
            changed += not same
            print(f"{name:24s} {digest[:16]}  {'same' if same else 'CHANGED'}  {time.time() - t:5.1f} s", flush=True)
            known[name] = digest
    if args.write:
        with open(FILE, "w") as f:
            json.dump({k: known[k] for k in CASES if k in known}, f, indent=1)
            f.write("\n")
    return 0 if args.write or changed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
