#!/usr/bin/env bash
# Configures and builds grainlab in ./build (Release). Used by run-main.sh and test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
