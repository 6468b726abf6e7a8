r"""
Thirty orbits started on L1, 50,000 iterates each (fig:smallepsmany)
====================================================================

fig:smallepsmany - "Dynamics for small +-eps values": thirty initial conditions evenly spaced in K along the line L1 (def:L1L2), iterated 50,000 times, for eps = 0.3 (a) and eps = -0.3 (b).

The scene file, ``examples/scenes/fig_smallepsmany.toml``:

.. code-block:: toml

   kind = "portrait"
   title = "Thirty orbits started on L1, 50,000 iterates each (fig:smallepsmany)"
   output = "out/fig_smallepsmany.png"
   n_steps = 50000
   n_orbits = 30
   K0_range = [-1.0, 0.5]      # initial heights on L1 (the paper does not print its range)
   line = "L1"
   color_by = "orbit"          # the paper's look; "region" colours every point by J_0u, J_0, J_1, J_R
   marker_size = 0.05
   dpi = 150
   figsize = [10.0, 11.0]

   [map]                       # the paper's figure parameters (sec:truncatedmapnumact)
   Omega0 = "OMEGA_G"          # 2 pi (sqrt 5 - 1)/2 = 3.88322...
   theta_w = "3*pi/4"
   tau0 = 1.0
   tau1 = 0.5
   lam = 0.5

   [[panels]]
   id = "a"
   eps = 0.3

   [[panels]]
   id = "b"
   eps = -0.3
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_smallepsmany.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_smallepsmany.png"), quick=True, keep_figure=True)
print(format_summary(summary))
