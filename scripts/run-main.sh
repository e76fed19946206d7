#!/usr/bin/env bash
# The README's first command: install dependencies, build, run the main job. The main job is two
# drained triaxial tests with the same [W] grading, side by side: preset quick-triaxial (the [W]
# contact law as published: a very strong, strongly dilating "sand") and preset karlsruhe-calibrated
# (micro-parameters calibrated to a laboratory test on Karlsruhe sand, docs/results/calibration-karlsruhe.md).
# Options (e.g. --threads 1) go to both runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build/grainlab run preset:quick-triaxial --out runs/quick-triaxial "$@"
build/grainlab run preset:karlsruhe-calibrated --out runs/karlsruhe-calibrated "$@"
