#!/usr/bin/env bash
# Build the documentation site into docs/_build/html, warnings as errors: the API reference from the
# docstrings, the user guide (docs/guide), the gallery (every example scene in quick mode and the
# scripts in examples/gallery, run now). Sets up the .venv with the docs extra first.
set -euo pipefail
cd "$(dirname "$0")/.."
# One set-up with both extras: the core is built once (or reused) for the tests and the docs alike.
bash scripts/setup.sh --extras test,docs
. .venv/bin/activate
export MPLBACKEND=Agg
rm -rf docs/_build/html docs/api/generated docs/gallery
python -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
echo "docs: docs/_build/html/index.html"
