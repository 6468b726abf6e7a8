"""The command line (python -m hovering): the demo command writes a PNG and a result that redraws
without computing; no command is a usage error.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest


def test_cli_demo_writes_png(tmp_path, capsys):
    from hovering.__main__ import main

    out = tmp_path / "demo.png"
    rc = main(["demo", "--out", str(out), "--n-steps", "100", "--n-orbits", "3", "--dpi", "40"])
    assert rc == 0
    data = out.read_bytes()
    assert len(data) > 1000 and data[:8] == b"\x89PNG\r\n\x1a\n"
    text = capsys.readouterr().out
    assert "scene demo (flow_portrait)" in text and "flow: 3 orbits" in text and "model: 3 orbits" in text
    assert "wrote" in text
    # demo is the packaged scene: its result is saved like any scene's and redraws without computing
    from hovering import scenes

    res = scenes.load_result(out.with_suffix(".npz"))
    # the physical flow beside its model (issue 21: the demo shows the package's subject)
    assert res.scene.kind == "flow_portrait" and res.scene.system.eps == -0.05 and res.meta["n_steps"] == 100
    assert res.flow.n_orbits == res.model.n_orbits == 3 and "regions" in res.scene.outputs.record
    plt.close("all")


def test_cli_requires_a_command():
    from hovering.__main__ import main

    with pytest.raises(SystemExit):
        main([])
