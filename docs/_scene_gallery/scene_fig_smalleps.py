r"""
Critical curves for \|eps\| = 0.3 (fig:smalleps)
================================================

fig:smalleps - "Critical curves for \|eps\| = 0.3". The four special orbits of sec:truncatedmapnumact: blue on L1 at K0 = K~\_c (eq:kcrit), orange on L1 at K~\_c + 0.05\|eps\|, green on L1 at K0 = 0, red on L2 at K0 = 0; legend: rho = <omega\_a> over the 50,000 iterates. Light grey: K = 0, L1, L2. Dashed black: corner-singularity curves. Black: leading-order curve k\_{eps,1}(phi; K0=0) (eq:keps1) in (a), k\_{eps,2}(phi; K0=0) (eq:keps2) in (b).

The scene file, ``examples/scenes/fig_smalleps.toml``:

.. code-block:: toml

   kind = "critical_orbits"
   title = "Critical curves for |eps| = 0.3 (fig:smalleps)"
   output = "out/fig_smalleps.png"
   n_steps = 50000
   rotation = "mean"           # the paper's rho; "birkhoff" = weighted Birkhoff average
   marker_size = 0.3
   leading_curve = true
   corner_curves = true
   dpi = 150
   figsize = [9.0, 11.0]

   [map]
   Omega0 = "OMEGA_G"
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

scene = load_scene("examples/scenes/fig_smalleps.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_smalleps.png"), quick=True, keep_figure=True)
print(format_summary(summary))
