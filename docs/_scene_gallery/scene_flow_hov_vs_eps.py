r"""
\|HOV\| of the full flow vs its truncated models vs eq:hovsetsize
=================================================================

Does the flow hover? \|HOV\| against eps for the full flow, its truncated models (onset arcs and arcs measured on the flow's corner curves, both with the measured forcing) and eq:hovsetsize, both signs of eps, with error bars; the same stratified points classified by flow and models.

The scene file, ``examples/scenes/flow_hov_vs_eps.toml``:

.. code-block:: toml

   kind = "flow_hovering_area"
   title = "|HOV| of the full flow vs its truncated models vs eq:hovsetsize"
   output = "out/flow_hov_vs_eps.png"
   n_steps = 2000
   samples = 2000
   seed = 0
   eps = [-0.2, -0.1, -0.05, 0.05, 0.1, 0.2]
   models = ["onset", "measured"]

   [system]
   V1 = { kind = "harmonic", omega = 1.0 }
   V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
   coupling = "bilinear"
   qw1 = -1.0
   qw2 = -0.5
   geometry = "step"

   [section]
   h = 1.0

   [integrator]
   rtol = 1e-10
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/flow_hov_vs_eps.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "flow_hov_vs_eps.png"), quick=True, keep_figure=True)
print(format_summary(summary))
