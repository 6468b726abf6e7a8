"""License and citation: the files a user and a packager look for, consistent with each other and
with the one place the version is written (CMakeLists.txt's project())."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def project_version():
    return re.search(r"project\(hovering VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text()).group(1)


def test_citation_names_this_version_and_the_paper():
    cff = (ROOT / "CITATION.cff").read_text()
    assert re.search(rf"^version: {re.escape(project_version())}$", cff, re.M), "CITATION.cff's version is stale"
    assert "Hovering Sets in Near Pseudo-Integrable Hamiltonian Impact Systems" in cff
    assert re.search(r"^license: MIT$", cff, re.M)


def test_the_license_choice_is_stated_alike_everywhere():
    lic = (ROOT / "LICENSE").read_text()
    assert lic.startswith("MIT License") and "GPL-3.0-or-later" in lic
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    text = meta["project"]["license"]["text"]
    assert "MIT" in text and "GPL-3.0-or-later" in text
    classifiers = meta["project"]["classifiers"]
    assert "License :: OSI Approved :: MIT License" in classifiers
    assert "License :: OSI Approved :: GNU General Public License v3 or later (GPLv3+)" in classifiers
    # Every notice the wheel carries exists (pyproject's wheel.license-files).
    for name in ("GPL-3.0.txt", "GSL-NOTICE.txt", "SLEEF-BSL-1.0.txt", "pybind11-BSD-3-Clause.txt"):
        assert (ROOT / "licenses" / name).stat().st_size > 500, name
    assert meta["tool"]["scikit-build"]["wheel"]["license-files"] == ["LICENSE", "licenses/*"]
