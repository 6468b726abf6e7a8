"""A wheel for other machines: `bash scripts/wheel.sh` builds hovering's wheel, repairs it with
auditwheel (GSL, its CBLAS and SLEEF copied in) and tags it manylinux; installed into a fresh venv it
runs with the system's copies of those libraries unavailable.

How "unavailable" is checked: (1) always, the process that imports the installed wheel and runs the
core lists its mapped files (/proc/self/maps): GSL and SLEEF must come from the wheel's
hovering.libs/, none from the system; (2) where a private mount namespace can be made (root, or an
unprivileged user namespace), the same run with every system file of libgsl, libgslcblas and
libsleef replaced by an empty one, so that loading any of them would fail ("file too short").

End-to-end (a wheel build, a venv, numpy and matplotlib installed into it): a minute or two.
"""

from __future__ import annotations

import glob
import os
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.e2e

# Run inside the fresh venv: one return of the flow (GSL's rk8pd) and one truncated-map orbit (the
# SLEEF lane kernels), then the libraries this process mapped.
PROBE = r"""
import json, numpy as np, hovering as hv
r = hv.Section(hv.paper.system(eps=0.05), hv.paper.H).return_map([0.3], [0.4], stepper="rk8pd")
it = hv.paper.truncated_map(eps=0.05).iterate(np.full(8, 0.1), np.linspace(0.2, 0.4, 8), 100)
maps = sorted({line.split()[-1] for line in open("/proc/self/maps") if "/" in line.split()[-1]})
print(json.dumps({"status": int(r.status[0]), "time": float(r.time[0]), "iter_ok": int(np.sum(np.asarray(it.status) == 0)),
                  "file": hv.__file__, "maps": maps}))
"""

SYSTEM_LIBS = ("libgsl.so", "libgslcblas.so", "libsleef.so")


def system_copies():
    """The system's files of the libraries the wheel must carry (every soname and version)."""
    found = []
    for d in ("/usr/lib/x86_64-linux-gnu", "/lib/x86_64-linux-gnu", "/usr/lib64", "/usr/lib", "/usr/local/lib"):
        for name in SYSTEM_LIBS:
            for f in glob.glob(os.path.join(d, name + "*")):
                real = os.path.realpath(f)
                if os.path.isfile(real) and real not in found:
                    found.append(real)
    return found


@pytest.fixture(scope="module")
def repaired_wheel(tmp_path_factory):
    out = tmp_path_factory.mktemp("dist")
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env["VIRTUAL_ENV"] = sys.prefix
    r = subprocess.run(
        ["bash", str(ROOT / "scripts" / "wheel.sh"), "--no-setup", str(out)],
        capture_output=True,
        text=True,
        env=env,
        timeout=3600,
    )
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-4000:]
    wheel = Path(r.stdout.strip().splitlines()[-1])
    assert wheel.is_file(), r.stdout[-2000:]
    return wheel


@pytest.fixture(scope="module")
def fresh_venv(repaired_wheel, tmp_path_factory):
    where = tmp_path_factory.mktemp("venv") / "v"
    venv.EnvBuilder(with_pip=True).create(where)
    py = where / "bin" / "python"
    r = subprocess.run(
        [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check", str(repaired_wheel)],
        capture_output=True,
        text=True,
        timeout=1800,
    )
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return py


def test_the_repaired_wheel_is_manylinux_and_carries_its_libraries_and_licenses(repaired_wheel):
    # The oldest policy this toolchain allows: Debian 12's glibc 2.36 / GCC 12 symbols need 2_35.
    assert "-manylinux_" in repaired_wheel.name and repaired_wheel.name.endswith("_x86_64.whl")
    names = zipfile.ZipFile(repaired_wheel).namelist()
    libs = [n for n in names if n.startswith("hovering.libs/")]
    for lib in ("libgsl-", "libgslcblas-", "libsleef-"):
        assert any(os.path.basename(n).startswith(lib) for n in libs), libs
    lic = [n for n in names if ".dist-info/licenses/" in n]
    for text in ("LICENSE", "GPL-3.0.txt", "GSL-NOTICE.txt", "SLEEF-BSL-1.0.txt", "pybind11-BSD-3-Clause.txt"):
        assert any(n.endswith(text) for n in lic), lic


def run_probe(py, cwd, wrap=()):
    r = subprocess.run([*wrap, str(py), "-c", PROBE], capture_output=True, text=True, cwd=cwd, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    import json

    return json.loads(r.stdout.strip().splitlines()[-1])


def check(out, py):
    import hovering as hv

    site = Path(out["file"]).resolve().parent
    # The installed wheel, not this checkout's python/hovering.
    assert str(site).startswith(str(py.parent.parent.resolve())), out["file"]
    # The same return as this process's build of the same source (one GSL, one algorithm): equal to
    # rounding, 1e-12 being far below any difference a wrong library or a broken build would make.
    ref = hv.Section(hv.paper.system(eps=0.05), hv.paper.H).return_map([0.3], [0.4], stepper="rk8pd")
    assert out["status"] == 0 and abs(out["time"] - float(ref.time[0])) < 1e-12 and out["iter_ok"] == 8, out
    mapped = out["maps"]
    for name in SYSTEM_LIBS:
        own = [m for m in mapped if os.path.basename(m).startswith(name.split(".so")[0] + "-")]
        assert own and all("hovering.libs" in m for m in own), (name, mapped)
        assert not [m for m in mapped if os.path.basename(m).startswith(name)], (name, mapped)


def test_the_wheel_runs_from_a_fresh_venv_on_its_own_copies(fresh_venv, tmp_path):
    check(run_probe(fresh_venv, tmp_path), fresh_venv)


def namespace_wrapper():
    """A command prefix that runs its command with the system's libgsl, libgslcblas and libsleef
    emptied (bind-mounted /dev/null over each file) in a private mount namespace, or None where
    this machine cannot make one."""
    unshare = shutil.which("unshare")
    if unshare is None:
        return None
    files = system_copies()
    binds = " && ".join(f"mount --bind /dev/null {f}" for f in files) or "true"
    for flags in (["-m"], ["-r", "-m"]):
        # The probe makes the very bind mounts the run will need (a namespace may allow no mounts).
        probe = subprocess.run([unshare, *flags, "sh", "-c", binds], capture_output=True, timeout=60)
        if probe.returncode == 0:
            return [unshare, *flags, "sh", "-c", binds + ' && exec "$0" "$@"'], files
    return None


def test_the_wheel_runs_with_the_system_libraries_unavailable(fresh_venv, tmp_path):
    wrapped = namespace_wrapper()
    if wrapped is None:
        # No namespace here: the /proc/self/maps check of the test above is the whole evidence.
        check(run_probe(fresh_venv, tmp_path), fresh_venv)
        return
    wrap, files = wrapped
    assert files, "no system copy of libgsl/libsleef found to hide (setup.sh installs them for the build)"
    # The emptied files really are unusable in that namespace: the system's GSL cannot load...
    gsl = next(f for f in files if os.path.basename(f).startswith("libgsl.so"))
    r = subprocess.run(
        [*wrap, sys.executable, "-c", f"import ctypes; ctypes.CDLL({gsl!r})"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode != 0, "the system's libgsl still loads inside the namespace: the check would prove nothing"
    # ... and the wheel runs there all the same.
    check(run_probe(fresh_venv, tmp_path, wrap), fresh_venv)
