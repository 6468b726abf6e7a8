r"""
The structure of the wall section (fig:wallsection), from the flow
==================================================================

fig:wallsection computed: the wall section Sigma\_h^{w,-} in the (q2, p2) plane and in the wall coordinates (theta, rho\_w) of eq:rhow, with its corner-singularity curves sigma\_R0^-, sigma\_01^-, sigma\_1R^- (red, blue, green) measured by bisecting the step system's region labels on n\_circles circles rho\_w = const, and the circle rho\_w = rho\_w\_fraction \* rho\_max(h) (eq:rhomaxh) coloured by region (J\_R yellow, J\_0 gray, J\_1 cyan). Right: trajectory segments through points of that circle (segments per arc, and one at each of its corner crossings), dots where they cross the wall. The paper draws the unperturbed case; eps != 0 (with a coupling) runs too.

The scene file, ``examples/scenes/fig_wallsection.toml``:

.. code-block:: toml

   kind = "wall_section"
   title = "The structure of the wall section (fig:wallsection), from the flow"
   output = "out/fig_wallsection.png"
   rho_w_fraction = 0.5
   n_theta = 720
   n_circles = 16
   bisections = 30
   segments = 2

   [system]
   V1 = { kind = "harmonic", omega = 1.0 }
   V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
   coupling = "none"
   eps = 0.0
   qw1 = -1.0
   qw2 = -0.5
   geometry = "step"

   [section]
   h = 1.0

   [integrator]
   rtol = 1e-12

   [outputs]
   record = ["regions", "trajectory"]
   trajectory_dt = 0.01
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_wallsection.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_wallsection.png"), quick=True, keep_figure=True)
print(format_summary(summary))
