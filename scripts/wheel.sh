#!/usr/bin/env bash
# A wheel for other Linux machines: build hovering's wheel (reusing the set-up's build of the core),
# then repair it with auditwheel, which copies the shared libraries it links that are not part of
# the manylinux base (GSL, its CBLAS, SLEEF) into hovering.libs/, points the module's RPATH at them
# and tags the wheel with the oldest manylinux policy its symbols allow (glibc and libstdc++ of this
# toolchain; Debian 12: manylinux_2_35). The license texts of what it bundles ride in the wheel's
# .dist-info/licenses (pyproject's wheel.license-files).
#
#   bash scripts/wheel.sh [OUT_DIR]              # set up .venv, then build into OUT_DIR (default dist/)
#   bash scripts/wheel.sh --no-setup [OUT_DIR]   # with the active venv as it is (set up before)
# The repaired wheel's path is the last line printed.
#
# The SIMD dispatch is unchanged: the wheel's core is the portable build (SSE2, with the AVX2 and
# AVX-512 lane kernels picked at run time). Publishing a release would upload this file (and the
# sdist, `pip download`-able source) with `twine upload`; no index carries hovering today.
set -euo pipefail
cd "$(dirname "$0")/.."
SETUP=1
if [ "${1:-}" = "--no-setup" ]; then SETUP=0; shift; fi
OUT=${1:-dist}
if [ "$SETUP" = 1 ]; then
  bash scripts/setup.sh
  # shellcheck disable=SC1091
  . .venv/bin/activate
fi
VENV_DIR=$(python -c 'import sys; print(sys.prefix)')
BUILD_DIR=$(cat "$VENV_DIR/hovering-build-dir" 2>/dev/null || echo "build/{wheel_tag}")
mapfile -t WHEEL_REQUIRES < <(python scripts/floors.py --requires wheel)
python -m pip install -q "${WHEEL_REQUIRES[@]}"
RAW=$(mktemp -d)
trap 'rm -rf "$RAW"' EXIT
mapfile -t BUILD_REQUIRES < <(python scripts/floors.py --requires build)
python -m pip install -q cmake ninja "${BUILD_REQUIRES[@]}"
echo "[wheel] building the wheel in $BUILD_DIR (the set-up's build of the core, reused)"
python -m pip wheel -q --no-deps --no-build-isolation . -w "$RAW" --config-settings=build-dir="$BUILD_DIR"
mkdir -p "$OUT"
echo "[wheel] repairing: $(basename "$RAW"/hovering-*.whl)"
auditwheel show "$RAW"/hovering-*.whl | sed 's/^/[wheel]   /'
# Without --plat auditwheel picks the most compatible (oldest) manylinux policy the wheel satisfies.
auditwheel repair -w "$OUT" "$RAW"/hovering-*.whl | sed 's/^/[wheel]   /'
ls -1t "$OUT"/hovering-*manylinux*.whl | head -n 1
