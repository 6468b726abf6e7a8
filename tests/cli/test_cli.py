"""The command line (python -m hovering): the demo command writes a PNG and a result that redraws
without computing; no command is a usage error.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest


def test_cli_demo_writes_png(tmp_path, capsys):
    from hovering.__main__ import main

    out = tmp_path / "demo.png"
    rc = main(["demo", "--out", str(out), "--steps", "200", "--orbits", "5", "--dpi", "40"])
    assert rc == 0
    data = out.read_bytes()
    assert len(data) > 1000 and data[:8] == b"\x89PNG\r\n\x1a\n"
    text = capsys.readouterr().out
    assert "eps = 0.3" in text and "eps = -0.3" in text and "wrote" in text and "scene demo (portrait)" in text
    # demo is the packaged scene: its result is saved like any scene's and redraws without computing
    from hovering import scenes

    res = scenes.load_result(out.with_suffix(".npz"))
    assert res.scene.kind == "portrait" and res.scene.color_by == "region" and res.meta["n_steps"] == 200
    assert [p.orbits.n_orbits for p in res.panels] == [5, 5]
    plt.close("all")


def test_cli_requires_a_command():
    from hovering.__main__ import main

    with pytest.raises(SystemExit):
        main([])
