r"""
Critical curves along the golden family, eps = 0.3 (fig:hoverinnc)
==================================================================

fig:hoverinnc - the critical curve for eps = 0.3 along the golden family of thm:hoveringc, Omega0 = Omega\_G - c eps/2, theta\_w = arccos(c sin(Omega\_G/2 - c eps/4)): (a) c = -0.9, near-maximal hovering set; (b) c = 0.9, near-minimal; (c) zoom of (b) on the small hovering set under the critical curve. Each orbit panel also shows the critical curve found numerically along L1 (hovering.analysis.critical\_curve), purple. window: the angles where the lowest hovering orbit of (b) dips below K = 0, and K in [K\_min, 0], each widened by pad = 0.5 of its size on both sides

The scene file, ``examples/scenes/fig_hoverinnc.toml``:

.. code-block:: toml

   kind = "critical_orbits"
   title = "Critical curves along the golden family, eps = 0.3 (fig:hoverinnc)"
   output = "out/fig_hoverinnc.png"
   n_steps = 50000
   rotation = "mean"
   marker_size = 0.3
   dpi = 150
   figsize = [9.0, 15.0]

   [map]
   tau0 = 1.0
   tau1 = 0.5
   lam = 0.5

   [[panels]]
   id = "a"
   eps = 0.3
   golden = { c = -0.9 }
   critical = true               # search the critical curve along L1 (as many iterates as the panel)

   [[panels]]
   id = "b"
   eps = 0.3
   golden = { c = 0.9 }
   critical = true               # search the critical curve along L1 (as many iterates as the panel)

   [[panels]]
   id = "c"
   zoom = { of = "b", on = "critical", pad = 0.5 }
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_hoverinnc.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_hoverinnc.png"), quick=True, keep_figure=True)
print(format_summary(summary))
