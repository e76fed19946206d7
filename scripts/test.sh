#!/usr/bin/env bash
# The README's second command: install dependencies, build, run every test (CTest; the Python suites
# on every core with pytest-xdist); then the command-line program again under AddressSanitizer +
# UndefinedBehaviorSanitizer (the `asan` preset of CMakePresets.json, build-asan/, target grainlab
# only), where any report fails: the fuzzer's forged checkpoints and packings (the binary files a
# user gets from someone else; 95-170 s) and one short whole run. The whole fuzzer and the hostile
# configs under ASan took 6 min (they run in the release build above); the unit tests under the
# sanitizers are a developer command (tests/README.md, *Sanitizers*): building them too doubled the
# sanitizer build (6 -> 11.5 min on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j"$(nproc)" "$@")

# Sanitizers: -fno-sanitize-recover=all makes every UBSan report fatal; ASan (and LeakSanitizer at
# exit) stop with a non-zero status anyway.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cmake --preset asan >/dev/null
cmake --build build-asan --target grainlab -j"$(nproc)"
OMP_WAIT_POLICY=passive GRAINLAB_BIN="$PWD/build-asan/grainlab" /usr/bin/python3 -m pytest -q -p no:cacheprovider \
  -n auto "tests/python/test_fuzz.py::test_fuzz_forged_checkpoints" "tests/python/test_fuzz.py::test_fuzz_check[packing]"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
# A short whole run (preparation, shearing, VTK, checkpoints, results) on two OpenMP threads, about
# 3 s: 40 spheres, loose equilibrium tolerances, 0.2 % of axial strain. Passive waiting: spinning
# OpenMP threads under ASan on a busy machine took 50x longer.
OMP_WAIT_POLICY=passive build-asan/grainlab run tests/data/small-triaxial.toml --out "$scratch/run" \
  --quiet --threads 2 --set sample.n_particles=40 --set test.final_axial_strain=0.002 \
  --set output.plots=false --set output.vtk_every_strain=0.001 --set output.checkpoint_every=0.001 \
  --set sample.prep_ramp_steps=2000 --set solver.unbalanced_tolerance=0.05 \
  --set solver.stress_tolerance=0.05 --set solver.servo_integral_steps=20
echo "sanitizers: forged checkpoints and packings and a short run clean under ASan + UBSan"
