r"""
The three directions that reach the corner (fig:corner\_directions), from the flow
==================================================================================

fig:corner\_directions computed from the flow: on the energy surface h the corner (qw1, qw2) is reached from three directions only, p\_R0 = (-p1w, P2), p\_01 = (p1w, -P2), p\_1R = (-p1w, -P2), P2 = sqrt(2 (h - h\_eps^w) - p1w^2) (eq:p2corner). For each direction and each p1w drawn, the corner state is traced back to Sigma\_h by the time-reversed smooth flow, and the step system's flow is run forward from there: the figure draws where it goes and the state it arrives in (the paper draws the three directions by hand). Panel (d): the three corner-singularity curves of Sigma\_h, traced the same way for n\_curve values of p1w (the paper's parametrization, Def:corner\_curve).

The scene file, ``examples/scenes/fig_corner_directions.toml``:

.. code-block:: toml

   kind = "corner_directions"
   title = "The three directions that reach the corner (fig:corner_directions), from the flow"
   output = "out/fig_corner_directions.png"
   p1w_fractions = [0.3, 0.7]  # p1w / sqrt(2 (h - h_eps^w)) of the drawn trajectories
   n_curve = 48

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
   rtol = 1e-12

   [outputs]
   record = ["trajectory"]
   trajectory_dt = 0.02
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_corner_directions.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_corner_directions.png"), quick=True, keep_figure=True)
print(format_summary(summary))
