r"""
Regions of Sigma\_h and their images, from the flow (fig:structure\_Sigma)
==========================================================================

fig:structure\_Sigma computed from the flow: the regions J\_R, J\_0, J\_1 (and J\_0u) of the tangential band and their images under the return map, in the (q2, p2) plane, in section coordinates (theta, I) and in normal coordinates (phi, K), with the tangency circle K = 0, its image and the measured corner-singularity curves. The paper draws it by hand.

The scene file, ``examples/scenes/fig_structure_sigma.toml``:

.. code-block:: toml

   kind = "sigma_structure"
   title = "Regions of Sigma_h and their images, from the flow (fig:structure_Sigma)"
   output = "out/fig_structure_sigma.png"
   grid = [360, 90]
   K_range = [-0.15, 0.04]
   marker_size = 1.5

   [system]
   V1 = { kind = "harmonic", omega = 1.0 }
   V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
   coupling = "bilinear"
   eps = 0.05
   qw1 = -1.0
   qw2 = -0.5
   geometry = "step"

   [section]
   h = 1.0

   [integrator]
   rtol = 1e-10

   [outputs]
   record = ["regions", "section", "states"]
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_structure_sigma.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_structure_sigma.png"), quick=True, keep_figure=True)
print(format_summary(summary))
