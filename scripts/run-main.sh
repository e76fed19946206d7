#!/usr/bin/env bash
# The README's first command: install dependencies, build, run the default triaxial test: the
# Karlsruhe sand calibrated to a laboratory test (docs/results/calibration-karlsruhe.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build/grainlab run preset:karlsruhe-calibrated --out runs/karlsruhe-calibrated "$@"
