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


# The build-time choices (CHANGELOG 0.3.0, "Build time"): the Python package's configuration as
# scikit-build-core makes it (SKBUILD, Release), read from the generated build.ninja.
def configure_module(tmp_path, *defines):
    pybind11 = pytest.importorskip("pybind11")
    return configure(
        tmp_path,
        "-DSKBUILD=ON",
        "-DCMAKE_BUILD_TYPE=Release",
        f"-Dpybind11_DIR={pybind11.get_cmake_dir()}",
        f"-DPython_EXECUTABLE={sys.executable}",
        *defines,
    )


def compile_lines(ninja: str, source: str) -> list[str]:
    """The FLAGS lines of every object built from `source` (one per target compiling it)."""
    blocks = ninja.split("\nbuild ")
    return [b for b in blocks if b.split(":", 1)[0].endswith(source + ".o")]


def test_the_module_binds_in_two_unity_sources_without_lto(tmp_path):
    rc, out, build = configure_module(tmp_path)
    assert rc == 0, out[-3000:]
    ninja = targets(build)
    assert "-flto" not in ninja  # pybind11's LTO of the bindings: off
    assert "Unity/unity_bindings_a_cxx.cxx.o" in ninja and "Unity/unity_bindings_b_cxx.cxx.o" in ninja
    assert "bind_flow.cpp.o" not in ninja
    # the core is never a unity build
    assert "hovering_core.dir/Unity" not in ninja


def test_unity_build_off_compiles_the_bindings_one_by_one(tmp_path):
    rc, out, build = configure_module(tmp_path, "-DCMAKE_UNITY_BUILD=OFF")
    assert rc == 0, out[-3000:]
    ninja = targets(build)
    assert "Unity/" not in ninja
    assert "bind_flow.cpp.o" in ninja and "bind_pickle.cpp.o" in ninja


def test_the_lane_kernels_compile_at_o2_in_release(tmp_path):
    # -O2 after Release's -O3 (the last -O wins): the six compilations of the two lane kernels.
    rc, out, build = configure_module(tmp_path)
    assert rc == 0, out[-3000:]
    ninja = targets(build)
    for source in ("truncated/lanes.cpp", "flow/taylor_lanes.cpp"):
        lines = compile_lines(ninja, source)
        assert lines, source
        for block in lines:
            flags = next(ln for ln in block.splitlines() if ln.strip().startswith("FLAGS ="))
            assert flags.rindex("-O2") > flags.index("-O3"), flags
    # the rest of the core keeps -O3 alone
    flags = next(ln for ln in compile_lines(ninja, "flow/tracer.cpp")[0].splitlines() if "FLAGS =" in ln)
    assert "-O3" in flags and "-O2" not in flags
