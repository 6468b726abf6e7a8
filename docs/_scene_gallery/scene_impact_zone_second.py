r"""
Does anything cross the impact zone? a second system: Tan(1, 0.5) x Harmonic(0.7), Vc = q1 q2 + 0.5 q1^2 q2, eps = +0.02 (Omega0 = 3.86)
========================================================================================================================================

The paper's open problem (sec:discussion): between the critical invariant curve (the zone's ceiling, s = 1) and the deformed torus tangent to the upper wall (its floor, s = 0), is the impact zone crossed by orbits or divided by invariant curves? a second system: Tan(1, 0.5) x Harmonic(0.7), Vc = q1 q2 + 0.5 q1^2 q2, eps = +0.02 (Omega0 = 3.86). For the flow and its truncated model side by side: a barrier scan along L1 (orbits classified by order statistics as circles, island chains or chaotic layers; two-sided barriers between neighbouring starts) and transits up from s = 0.05 and down from s = 0.95. The model runs model\_factor times more steps (it is ~1000x cheaper per step). docs/impact-zone.md reads it.

The scene file, ``examples/scenes/impact_zone_second.toml``:

.. code-block:: toml

   kind = "impact_zone"
   title = "Does anything cross the impact zone? a second system: Tan(1, 0.5) x Harmonic(0.7), Vc = q1 q2 + 0.5 q1^2 q2, eps = +0.02 (Omega0 = 3.86)"
   output = "out/impact_zone_second.png"
   n_starts = 40
   n_steps = 20000
   transit_orbits = 40
   transit_steps = 100000
   model_factor = 20
   model = "measured"
   line = "L1"
   critical_steps = 20000
   keep = 2000

   [system]
   V1 = { kind = "tan", omega = 1.0, alpha = 0.5 }
   V2 = { kind = "harmonic", omega = 0.7 }
   coupling = [[1.0, 1, 1], [0.5, 2, 1]]
   eps = 0.02
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

scene = load_scene("examples/scenes/impact_zone_second.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "impact_zone_second.png"), quick=True, keep_figure=True)
print(format_summary(summary))
