#!/usr/bin/env bash
# Quick start 1: set everything up, then run the demo scene that writes a phase-portrait figure.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
. .venv/bin/activate
mkdir -p out
python -m hovering demo --out "${1:-out/hovering_demo.png}"
