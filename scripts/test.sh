#!/usr/bin/env bash
# Quick start 2: set everything up, then run the whole test suite: ctest (C++) and pytest (Python).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
. .venv/bin/activate
echo "[test] C++ unit tests (ctest)"
cmake -S . -B build/ctest -G Ninja -DCMAKE_BUILD_TYPE=Release -DHOVERING_BUILD_TESTS=ON >/dev/null
cmake --build build/ctest
(cd build/ctest && ctest --output-on-failure)
echo "[test] Python tests (pytest)"
python -m pytest tests
