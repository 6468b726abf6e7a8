#!/usr/bin/env bash
# All set-up on a fresh Debian machine, idempotent: system libraries (apt, only if missing), a
# virtual environment in .venv, CMake/Ninja for the C++ tests, and the hovering package itself.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(g++ pkg-config libgsl-dev libeigen3-dev libsleef-dev catch2 libtomlplusplus-dev libcli11-dev)
PY=${PYTHON:-python3}

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

if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv"
  "$PY" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate
python -m pip install -q --upgrade pip
python -m pip install -q cmake ninja
echo "[setup] building and installing hovering (C++ core + Python module)"
python -m pip install -q ".[test]"
python -c "import hovering; print('[setup] hovering', hovering.__version__, '- SIMD AVX2:', hovering.simd_is_avx2())"
