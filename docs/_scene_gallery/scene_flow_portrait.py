r"""
Full return map vs truncated model, eps = -0.05 (hovers: sin(Omega0/2) < 0)
===========================================================================

The full return map next to its truncated model: the picture a researcher makes first. The same starts on L1 are iterated by the flow (FlowMap: GSL rk8pd, normal coordinates from the measured tangential curve) and by its truncated model (onset-parameter arcs, measured forcing); every point is coloured by the region of its return (J\_0u, J\_0, J\_1, J\_R); the flow's corner- singularity curves are measured by bisection on circles K < 0.

The scene file, ``examples/scenes/flow_portrait.toml``:

.. code-block:: toml

   kind = "flow_portrait"
   title = "Full return map vs truncated model, eps = -0.05 (hovers: sin(Omega0/2) < 0)"
   output = "out/flow_portrait.png"
   n_steps = 2000              # returns per orbit (and model steps)
   n_orbits = 16
   K0_range = [-0.08, 0.04]
   model = "measured"          # or "first_mode": the paper's F_eps with amplitude eps b1
   corner_K = 14               # circles on which the flow's corner curves are measured
   marker_size = 0.4
   dpi = 140

   [system]                    # the effects this scene simulates, and nothing else
   V1 = { kind = "harmonic", omega = 1.0 }
   V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
   coupling = "bilinear"       # Vc = q1 q2
   eps = -0.05
   qw1 = -1.0
   qw2 = -0.5
   geometry = "step"

   [section]
   h = 1.0

   [integrator]
   stepper = "rk8pd"
   rtol = 1e-10
   atol = 1e-10

   [outputs]
   record = ["regions"]        # drop it and no crossing of q1 = qw1 is booked; orbits then get one colour each
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/flow_portrait.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "flow_portrait.png"), quick=True, keep_figure=True)
print(format_summary(summary))
