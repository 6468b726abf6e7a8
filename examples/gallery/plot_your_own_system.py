"""
Your own system: from potentials to a FlowMap, its truncated model and its hovering set
=======================================================================================

A system that is not the paper's: a Tan well ``V1 = Tan(omega=1, alpha=0.5)`` in q1, a harmonic
``V2 = Harmonic(omega=0.7)`` in q2, the coupling ``Vc = q1 q2 + 0.5 q1^2 q2`` and the step
``{q1 < -1, q2 < -0.5}`` at energy h = 1. The checklist, in the order to run it:

1. **the onset parameters** (sec:parametersdef): Omega0, tau0, tau1, lambda, theta_w - they say
   which regime the truncated model is in;
2. **b1 and the effective eps**: the model acts with ``eps b1`` (b1: the first sine mode of the
   measured forcing f of eq:defoff), which can be much larger than eps. The sign of eps that
   hovers is ``sign(sin(Omega0 / 2) * b1)``, for every Omega0: its period in Omega0 is 4 pi, so
   ``Omega0 mod 2 pi`` does not decide it (Omega0 and Omega0 + 2 pi hover for opposite signs). Where
   b1 is 0 within its measured error (a coupling even in q2) there is no first-order forcing and the
   higher modes decide; ``repr(fm)`` and ``fm.theory().note`` say so;
3. **the band**: the heights K where the normal coordinates hold; starts outside it are refused;
4. **the theory** (thm:hovering generalised to every Omega0): does it hover, and how much;
5. **the flow and its model side by side**, then **the hovering set measured** on both and
   compared point by point.
"""

# %%
# The system and its onset parameters
# -----------------------------------
import matplotlib.pyplot as plt
import numpy as np

import hovering
from hovering.plot.primitives import plot_orbits

sys = hovering.StepSystem(
    V1=hovering.Tan(omega=1.0, alpha=0.5),
    V2=hovering.Harmonic(omega=0.7),
    coupling=hovering.Polynomial({(1, 1): 1.0, (2, 1): 0.5}),
    eps=0.02,
    qw1=-1.0,
    qw2=-0.5,
)
fm = hovering.FlowMap(sys, h=1.0)  # rk8pd at rtol 1e-10 by default
p = fm.onset
print(f"Omega0 = {p.Omega0:.4f} (sin(Omega0/2) = {np.sin(p.Omega0 / 2):+.4f}), tau0 = {p.tau0:.4f}, "
      f"tau1 = {p.tau1:.4f}, lambda = {p.lam:.4f}, theta_w = {p.theta_w:.4f}")  # fmt: skip

# %%
# b1, the effective eps, the band, the theory
# -------------------------------------------
# ``repr(fm)`` ends with a comment that says it: here the model acts with eps b1 = 0.090, 4.5 times
# the coupling's eps - check it before trusting a small-eps intuition.
b = fm.forcing_coefficients()
print(f"b1 = {b[0]:.4f} (error bound {fm.forcing_tolerance():.1g}); effective eps = eps b1 = {sys.eps * b[0]:.4f}; "
      f"higher modes {np.round(b[1:4], 5)}")  # fmt: skip
print("band:", fm.valid_band())
th = fm.theory()
# The sign of eps that hovers: sign(sin(Omega0/2) b1), whatever Omega0 (period 4 pi).
print(f"sign(sin(Omega0/2) b1) = {int(np.sign(np.sin(p.Omega0 / 2) * b[0])):+d}")
print(f"hovers: {th.hovers} (sign of eps that hovers: {th.hovering_sign:+d}); eq:hovsetsize area {th.area:.4f}")
print(th.note)

# %%
# The flow and its truncated model from the same starts
# -----------------------------------------------------
# Twelve starts on the line L1, 600 returns of the flow (C++, both cores) and 600 steps of the
# model (onset arcs with the measured forcing), coloured by the region each return is taken from.
model = fm.truncated()
K0 = np.linspace(-0.12, 0.06, 12)
flow = fm.iterate(fm.L1(K0), K0, 600, record=("orbit", "regions"))
mod = model.iterate(fm.L1(K0), K0, 600, record=("orbit", "regions"))
print("flow statuses:", np.unique(flow.status, return_counts=True))

fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True, constrained_layout=True)
for ax, res, title in zip(axes, (flow, mod), ("the flow's return map", "its truncated model")):
    plot_orbits(ax, res, color_by="region", s=0.4)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlim(-np.pi, np.pi)
    ax.set_xlabel(r"$\phi$")
    ax.set_title(title)
axes[0].set_ylabel("K")

# %%
# The hovering set on the flow and on its models, point by point
# --------------------------------------------------------------
# ``compare_hovering`` judges the same samples of the flow's box with the flow and with each
# model: the agreement and where they disagree. Small counts here (the docs build runs this);
# raise ``n_samples`` and ``n_steps`` for a measurement.
cmp = hovering.compare_hovering(fm, n_samples=400, n_steps=200)
print(cmp)
