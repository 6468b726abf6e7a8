"""Central differences of a map, with their own error estimate: the oracle of the Jacobian tests.

``D(h)`` is the central difference at step h. Its error is truncation ``c h^2`` plus noise
``2 delta / (2 h)``, where delta bounds how much the computed map can differ from a smooth function
between two nearby points (rounding for the truncated map; the integration error of a return for
the flow). ``D(2h) - D(h) = 3 c h^2`` estimates the truncation, so

    |D(h) - J| <= |D(h) - D(2h)| / 3 + delta / h    (per entry, up to O(h^4)),

and the tests accept J when it is within twice that bound. The stencil must stay on one smooth
branch of the map: ``same_branch`` tells whether its points share the centre's region (truncated)
or itinerary (flow); a stencil across a corner curve or a change of itinerary has no derivative.
"""

from __future__ import annotations

import numpy as np


def wrap(x):
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi


def stencil(phi, K, h):
    """The 8 points (phi +- h, K), (phi, K +- h) at steps h and 2h, shape (8,) each, in the order
    [(+h, 0), (-h, 0), (0, +h), (0, -h)] for h, then for 2h."""
    d = np.array([(1, 0), (-1, 0), (0, 1), (0, -1)], dtype=float)
    steps = np.concatenate([d * h, d * 2 * h])
    return phi + steps[:, 0], K + steps[:, 1]


def differences(images_phi, images_K, h):
    """D(h) and D(2h), each (2, 2), from the images of :func:`stencil`'s 8 points."""
    out = []
    for j, s in ((0, h), (4, 2 * h)):
        D = np.empty((2, 2))
        for col in range(2):
            a, b = j + 2 * col, j + 2 * col + 1
            D[0, col] = wrap(images_phi[a] - images_phi[b]) / (2 * s)
            D[1, col] = (images_K[a] - images_K[b]) / (2 * s)
        out.append(D)
    return out


def bound(Dh, D2h, delta, h):
    """The per-entry error bound of D(h) (see the module docstring)."""
    return np.abs(Dh - D2h) / 3 + delta / h
