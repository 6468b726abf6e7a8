r"""
Area of the hovering set against eps (eq:hovsetsize)
====================================================

\|HOV(eps)\| against eps (not a figure of the paper: the check of eq:hovsetsize and thm:hovering). HOV(eps) = points that impact under F\_0 but never (here: within n\_steps iterates) under F\_eps, measured by hovering.analysis.hovering\_area (stratified sampling of [-pi, pi) x [K\_low, 0)). The default box [-pi, pi) x [-2\|eps\|/sin(Omega0/2), 0) holds the critical band of eq:hovsetsize. Error bars: 2 sampling sigma + the change over the last doubling of the iterate count. Lines: the leading order eps (sin theta\_w - theta\_w cos theta\_w) / sin(Omega0/2), 0 for eps <= 0. HOV by its definition over the whole band below K = 0: it then also holds the period-2 resonance island of the standard map (rho = pi, near K = pi - Omega\_G = -0.742), which lies inside J\_0 and never impacts - for either sign of eps (see the report on thm:hovering).

The scene file, ``examples/scenes/fig_hov_vs_eps.toml``:

.. code-block:: toml

   kind = "hovering_area"
   title = "Area of the hovering set against eps (eq:hovsetsize)"
   output = "out/fig_hov_vs_eps.png"
   n_steps = 20000
   samples = 100000
   seed = 0
   eps = [-0.3, -0.1, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6]
   dpi = 150

   [map]
   tau0 = 1.0
   tau1 = 0.5
   lam = 0.5

   [[series]]
   label = "Omega0 = Omega_G, theta_w = 3 pi/4"
   Omega0 = "OMEGA_G"
   theta_w = "3*pi/4"

   [[series]]
   label = "golden family c = -0.9"
   golden_c = -0.9

   [[series]]
   label = "golden family c = 0.9"
   golden_c = 0.9

   [[series]]
   label = "Omega0 = Omega_G, theta_w = 3 pi/4, whole band K >= -3"
   Omega0 = "OMEGA_G"
   theta_w = "3*pi/4"
   K_low = -3.0
   color = "C3"
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_hov_vs_eps.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_hov_vs_eps.png"), quick=True, keep_figure=True)
print(format_summary(summary))
