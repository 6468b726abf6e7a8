#!/usr/bin/env bash
# Quick start 2: set everything up, then run the whole test suite: ctest (C++) and pytest (Python).
#
#   bash scripts/test.sh            # newest releases of every dependency (what pip resolves today)
#   bash scripts/test.sh --oldest   # the declared minimums (pyproject.toml floors), in .venv-oldest;
#                                   # pytest only: the C++ tests do not involve a Python dependency
# Extra arguments after -- go to pytest (e.g. -- -m "not slow"). Without them the whole suite runs,
# slow and end-to-end tests included, all but the stress loops (-m "not stress": 2,600 processes that
# repeat what the quick exit-race test covers, ~15 minutes; CI runs them as `-- -m stress`); a bare
# `python -m pytest tests` is the quick local run (pyproject's addopts leave out slow and e2e).
set -euo pipefail
cd "$(dirname "$0")/.."

OLDEST=0
PYTEST_ARGS=(-m "not stress")
while [ $# -gt 0 ]; do
  case "$1" in
    --oldest) OLDEST=1 ;;
    --) shift; PYTEST_ARGS=("$@"); break ;;
    *) echo "test.sh: unknown option $1 (allowed: --oldest, -- PYTEST_ARGS)" >&2; exit 2 ;;
  esac
  shift
done

PY=${PYTHON:-python3}
VENV=.venv
[ -n "${PYTHON:-}" ] && VENV=".venv-$(basename "$PY")"
if [ "$OLDEST" = 1 ]; then
  bash scripts/setup.sh --oldest
  VENV="$VENV-oldest"
else
  bash scripts/setup.sh
fi
# shellcheck disable=SC1091
. "$VENV/bin/activate"
if [ "$OLDEST" = 0 ]; then
  echo "[test] C++ unit tests (ctest)"
  # shellcheck source=scripts/compiler_cache.sh
  . scripts/compiler_cache.sh
  cmake -S . -B build/ctest -G Ninja -DCMAKE_BUILD_TYPE=Release -DHOVERING_BUILD_TESTS=ON -DHOVERING_BUILD_APPS=ON >/dev/null
  cmake --build build/ctest
  (cd build/ctest && ctest --output-on-failure)
fi
echo "[test] Python tests (pytest) with $(python -c 'import sys, numpy, matplotlib; print("Python", sys.version.split()[0], "numpy", numpy.__version__, "matplotlib", matplotlib.__version__)')"
python -m pytest tests "${PYTEST_ARGS[@]}"
