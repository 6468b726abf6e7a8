r"""
The unperturbed tangency line on the wall section (fig:Sigma\_0\_wall), from the flow
=====================================================================================

fig:Sigma\_0\_wall computed: the unperturbed wall section Sigma\_h^{\*,-} (q1 = qw1) in the (q2, p2) plane. Its tangency line Xi^0\_wall (p1 = 0: trajectories that touch the line q1 = qw1) divides it into Sigma\_h^> outside (turning back before the line: J\_0u) and Sigma\_h^{w,-} inside, whose points are coloured by the region of the step system's return through them (J\_R, J\_0, J\_1). The caption's seven points of the tangency line (1, 7 above the corner; 2, 6 at it; 3-5 on the right wall below it) with their trajectories, computed by the flow: each starts where the tangential curve (traced back from the wall by the core) meets Sigma\_h.

The scene file, ``examples/scenes/fig_sigma0_wall.toml``:

.. code-block:: toml

   kind = "wall_tangency"
   title = "The unperturbed tangency line on the wall section (fig:Sigma_0_wall), from the flow"
   output = "out/fig_sigma0_wall.png"
   grid = [180, 40]            # [n_theta, n_rho] points of Sigma_h^{w,-} labelled by the flow
   n_points = 400

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

scene = load_scene("examples/scenes/fig_sigma0_wall.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_sigma0_wall.png"), quick=True, keep_figure=True)
print(format_summary(summary))
