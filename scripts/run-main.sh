#!/usr/bin/env bash
# The README's first command: install dependencies, build, run the default triaxial test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build/grainlab run preset:quick-triaxial --out runs/quick-triaxial "$@"
