"""The C++ build's configuration: a top-level `cmake -S . -B build` needs only GSL, Eigen and SLEEF
(the tests and the sweep executable are built when their libraries are found, AUTO), and a missing
dependency names the Debian package that provides it (the README's promise).

Configuration only (no compilation): a few seconds each. Missing libraries are simulated with
CMAKE_DISABLE_FIND_PACKAGE_<name>, which makes find_package fail as on a machine without them.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# The venv's cmake and ninja (scripts/setup.sh installs them there) even when it is not activated.
SEARCH = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])


def configure(tmp_path, *defines):
    cmake, ninja = shutil.which("cmake", path=SEARCH), shutil.which("ninja", path=SEARCH)
    assert cmake, "cmake is needed (scripts/setup.sh installs it into the venv)"
    gen = ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"] if ninja else []
    r = subprocess.run(
        [cmake, "-S", str(ROOT), "-B", str(tmp_path / "b"), *gen, *defines],
        capture_output=True,
        text=True,
        timeout=300,
    )
    return r.returncode, r.stdout + r.stderr, tmp_path / "b"


def targets(build: Path) -> str:
    return (build / "build.ninja").read_text() if (build / "build.ninja").exists() else (build / "Makefile").read_text()


@pytest.mark.parametrize(
    "package, debian",
    [("GSL", "libgsl-dev"), ("Eigen3", "libeigen3-dev")],
)
def test_a_missing_core_dependency_names_its_debian_package(tmp_path, package, debian):
    rc, out, _ = configure(tmp_path, f"-DCMAKE_DISABLE_FIND_PACKAGE_{package}=TRUE")
    assert rc != 0
    assert f"apt-get install {debian}" in " ".join(out.split()), out[-2000:]


def test_without_the_test_and_app_libraries_the_core_still_configures(tmp_path):
    rc, out, build = configure(
        tmp_path, "-DCMAKE_DISABLE_FIND_PACKAGE_tomlplusplus=TRUE", "-DCMAKE_DISABLE_FIND_PACKAGE_Catch2=TRUE"
    )
    assert rc == 0, out[-3000:]
    flat = " ".join(out.split())
    # AUTO left both out and said which packages would bring them back.
    assert "hovering_sweep) left out: sudo apt-get install libtomlplusplus-dev" in flat, flat[-2000:]
    assert "ctest unit tests left out: sudo apt-get install libtomlplusplus-dev catch2" in flat, flat[-2000:]
    ninja = targets(build)
    assert "hovering_core" in ninja
    assert "hovering_sweep" not in ninja and "test_flow" not in ninja


def test_asking_for_the_tests_without_catch2_is_an_error_naming_it(tmp_path):
    rc, out, _ = configure(tmp_path, "-DHOVERING_BUILD_TESTS=ON", "-DCMAKE_DISABLE_FIND_PACKAGE_Catch2=TRUE")
    assert rc != 0
    assert "apt-get install catch2" in " ".join(out.split()), out[-2000:]


def test_auto_builds_the_tests_and_the_executable_where_their_libraries_are(tmp_path):
    # scripts/setup.sh installs Catch2, toml++, nlohmann-json and CLI11, so AUTO finds them here.
    rc, out, build = configure(tmp_path)
    assert rc == 0, out[-3000:]
    ninja = targets(build)
    assert "hovering_sweep" in ninja and "test_flow" in ninja


def test_an_option_value_outside_on_off_auto_is_refused(tmp_path):
    rc, out, _ = configure(tmp_path, "-DHOVERING_BUILD_APPS=maybe")
    assert rc != 0
    assert "HOVERING_BUILD_APPS=maybe: allowed values are ON, OFF and AUTO" in " ".join(out.split())
