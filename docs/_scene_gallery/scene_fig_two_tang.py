r"""
The two tangent tori of the unperturbed oscillators-step system (fig:two-tang)
==============================================================================

fig:two-tang computed: the two iso-energy tangent tori of the unperturbed system (eps = 0), projected to (q1, q2), (q1, p1) and (q2, p2), with trajectory segments sampled densely by the flow. The blue torus (H1 = V1(qw1)) touches the right wall's line, the red one (H2 = V2(qw2)) the upper wall's. The tori are those of the smooth flow: no coupling, no walls, no event search.

The scene file, ``examples/scenes/fig_two_tang.toml``:

.. code-block:: toml

   kind = "tangent_tori"
   title = "The two tangent tori of the unperturbed oscillators-step system (fig:two-tang)"
   output = "out/fig_two_tang.png"
   n_returns = 4               # returns to Sigma_h drawn per trajectory
   n_points = 400

   [system]
   V1 = { kind = "harmonic", omega = 1.0 }
   V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
   coupling = "none"
   eps = 0.0
   qw1 = -1.0
   qw2 = -0.5
   geometry = "none"           # tangent trajectories only touch the walls' lines

   [section]
   h = 1.0

   [integrator]
   rtol = 1e-12

   [outputs]
   record = ["trajectory"]
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

scene = load_scene("examples/scenes/fig_two_tang.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_two_tang.png"), quick=True, keep_figure=True)
print(format_summary(summary))
