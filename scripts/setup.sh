#!/usr/bin/env bash
# All set-up on a fresh Debian machine, idempotent: system libraries (apt, only if missing), a
# virtual environment, CMake/Ninja for the C++ tests, and the hovering package itself.
#
#   bash scripts/setup.sh            # .venv with what pip resolves today (the newest releases)
#   bash scripts/setup.sh --oldest   # .venv-oldest with every declared minimum (scripts/floors.py)
#   bash scripts/setup.sh --extras test,docs   # the extras to install (default: test)
#
# One build of the core per venv, reused: the package is built without pip's build isolation (its
# build requirements live in the venv, so every path the compiler sees stays the same) in a fixed
# tree, build/<wheel tag> (build/oldest for --oldest). A later run recompiles only what changed
# since (nothing at the same commit) and re-installs in seconds.
#
# PYTHON=python3.13 picks another interpreter (its venv is then .venv-python3.13[-oldest]).
set -euo pipefail
cd "$(dirname "$0")/.."

OLDEST=0
EXTRAS=test
while [ $# -gt 0 ]; do
  case "$1" in
    --oldest) OLDEST=1 ;;
    --extras) [ $# -ge 2 ] || { echo "setup.sh: --extras needs a comma-separated list" >&2; exit 2; }
              EXTRAS=$2; shift ;;
    *) echo "setup.sh: unknown option $1 (allowed: --oldest, --extras LIST)" >&2; exit 2 ;;
  esac
  shift
done

APT_PACKAGES=(g++ pkg-config libgsl-dev libeigen3-dev libsleef-dev catch2 libtomlplusplus-dev libcli11-dev nlohmann-json3-dev)
PY=${PYTHON:-python3}
VENV=.venv
[ -n "${PYTHON:-}" ] && VENV=".venv-$(basename "$PY")"
[ "$OLDEST" = 1 ] && VENV="$VENV-oldest"

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# A Python without a working venv module (Debian's python3 without python3-venv) needs the package.
if ! "$PY" -c "import venv, ensurepip" >/dev/null 2>&1; then missing+=(python3-venv python3-dev); fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "[setup] installing Debian packages: ${missing[*]}"
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "[setup] creating $VENV"
  "$PY" -m venv "$VENV"
fi
# shellcheck disable=SC1091
. "$VENV/bin/activate"
python -m pip install -q --upgrade pip
if [ "$OLDEST" = 1 ]; then
  # pip applies PIP_CONSTRAINT to the isolated build environment too (pybind11, scikit-build-core).
  mkdir -p build
  python scripts/floors.py test > build/floors.txt
  echo "[setup] the declared minimums: $(tr '\n' ' ' < build/floors.txt)"
  export PIP_CONSTRAINT="$PWD/build/floors.txt"
  BUILD_DIR=build/oldest
else
  BUILD_DIR="build/{wheel_tag}"
fi
# The build requirements (pyproject's [build-system], at their floors with --oldest) and CMake/Ninja,
# in the venv: the build below runs without isolation, in the same environment every time.
mapfile -t BUILD_REQUIRES < <(python scripts/floors.py --requires build)
python -m pip install -q cmake ninja "${BUILD_REQUIRES[@]}"
# shellcheck source=scripts/compiler_cache.sh
. scripts/compiler_cache.sh
echo "[setup] building (or re-using the build of) hovering's C++ core and installing it into $VENV${CMAKE_CXX_COMPILER_LAUNCHER:+ (compiler launcher: $CMAKE_CXX_COMPILER_LAUNCHER)}"
start=$(date +%s)
python -m pip install -q --no-build-isolation ".[$EXTRAS]" --config-settings=build-dir="$BUILD_DIR"
echo "[setup] build and install: $(( $(date +%s) - start )) s"
# scripts/wheel.sh builds its wheel in the same tree (the venv's build requirements, no recompile).
echo "$BUILD_DIR" > "$VENV/hovering-build-dir"
python -c "import hovering, numpy; print('[setup] hovering', hovering.__version__, '- numpy', numpy.__version__, '- SIMD width:', hovering.simd_width())"
