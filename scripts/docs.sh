#!/usr/bin/env bash
# Build the documentation site into docs/_build/html, warnings as errors: the API reference from the
# docstrings, the user guide (docs/guide), the gallery (every example scene in quick mode and the
# scripts in examples/gallery, run now). Sets up the .venv with the docs extra first.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
. .venv/bin/activate
python -m pip install -q --disable-pip-version-check ".[docs]" --config-settings=build-dir="build/{wheel_tag}"
export MPLBACKEND=Agg
rm -rf docs/_build/html docs/api/generated docs/gallery
python -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
echo "docs: docs/_build/html/index.html"
