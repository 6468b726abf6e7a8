r"""
Golden family c = -0.9 at large \|eps\| (fig:epsbig)
====================================================

fig:epsbig - the golden family (thm:hoveringc) with c = -0.9 at large \|eps\|: (a) eps = 0.6, (b) eps = 0.92, (c) zoom on the islands of (b), (d) eps = -0.92 with the (Omega0, theta\_w) of (b), (e) eps = -0.92 with its own golden-family (Omega0, theta\_w). Besides the four special orbits, (a) and (b) show the critical curve found along L1, and (b) four impacting island orbits. Their starts were found by scanning the impact zone of (b) (phi in [0.2, 2], K in [-0.65, 0]) for regular orbits (weighted-Birkhoff regularity > 10 digits over 20,000 iterates) and then walking out from each island centre to the outermost regular start, so that each orbit traces its island's outer ring: A  rho = 6 pi/5 (period 5), itinerary in J\_0 and J\_R: the upper chain, bounded by K = 0; B  rho = 5 pi/4 (period 8), visits J\_0, J\_1 and J\_R: upper-left chain, cut by phi\_01; C  rho = 6 pi/5 (period 5), visits J\_0 and J\_1: the large lower island, cut by phi\_1R; D  rho = 4 pi/3 (period 3), visits J\_0 and J\_1. the default search range (down to 3 K~\_c) finds a period-3 island in J\_0 at K ~ -2.7 first the green orbit wanders up to K ~ 4 in the chaotic sea of the standard map: keep the hovering region readable window: bounding box of the points of the island orbits that lie in J\_1 or J\_R, widened by 15%

The scene file, ``examples/scenes/fig_epsbig.toml``:

.. code-block:: toml

   kind = "critical_orbits"
   title = "Golden family c = -0.9 at large |eps| (fig:epsbig)"
   output = "out/fig_epsbig.png"
   n_steps = 50000
   rotation = "mean"
   marker_size = 0.3
   layout = [2, 3]
   figsize = [19.0, 12.0]
   dpi = 130

   [map]
   tau0 = 1.0
   tau1 = 0.5
   lam = 0.5

   [[panels]]
   id = "a"
   eps = 0.6
   golden = { c = -0.9 }
   critical = true               # search the critical curve along L1 (as many iterates as the panel)

   [[panels]]
   id = "b"
   eps = 0.92
   golden = { c = -0.9 }
   critical = { K_range = [-1.5, 0.5] }
   ylim = [-1.45, 1.6]

     [[panels.orbits]]
     label = "island A, period 5"
     phi0 = 0.736
     K0 = -0.05

     [[panels.orbits]]
     label = "island B, period 8"
     phi0 = 0.208
     K0 = -0.10

     [[panels.orbits]]
     label = "island C, period 5"
     phi0 = 0.444
     K0 = -0.515

     [[panels.orbits]]
     label = "island D, period 3"
     phi0 = 0.292
     K0 = -0.26

   [[panels]]
   id = "c"
   zoom = { of = "b", on = "islands", orbits = ["island A, period 5", "island B, period 8", "island C, period 5", "island D, period 3"], pad = 0.15 }

   [[panels]]
   id = "d"
   eps = -0.92
   golden = { c = -0.9, eps = 0.92 }

   [[panels]]
   id = "e"
   eps = -0.92
   golden = { c = -0.9 }
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir('/work/wt-layers')
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/fig_epsbig.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "fig_epsbig.png"), quick=True, keep_figure=True)
print(format_summary(summary))
