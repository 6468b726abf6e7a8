"""Write the pickles and NPZ files of tests/data/legacy with the hovering of main at commit 22d49ca
(before maps, systems and potentials had one record each): tests/package/test_records.py loads them
with today's package and checks that each object steps bit for bit as it did then (the expected
images are stored beside them, computed by the old objects).

Run from the repository root with that version installed: ``python tests/data/legacy/make_legacy.py``.
"""

import pickle
from pathlib import Path

import numpy as np

import hovering as hv

OUT = Path(__file__).resolve().parent
PAPER = dict(Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4, tau0=1.0, tau1=0.5, lam=0.5)


def system(eps):
    return hv.StepSystem(
        V1=hv.Harmonic(1.0), V2=hv.Tan(1.4, 0.7), coupling=hv.Bilinear(), eps=eps, qw1=-1.0, qw2=-0.5, geometry="step"
    )


def main():
    m = hv.TruncatedMap(eps=0.3, **PAPER)
    grid = np.concatenate([-(np.linspace(1.0, 0.0, 40) ** 2), np.linspace(0.05, 1.0, 20)])
    objects = {
        "truncated": m,
        "truncated_capped": hv.TruncatedMap(
            eps=-0.2, Omega0=1.3, theta_w=2.0, tau0=-0.7, tau1=-0.4, lam=0.7, K_max=0.4
        ),
        "family": hv.TruncatedFamily.from_map(m, grid, forcing=(1.0, 0.25, -0.1)),
        "flow_normal": hv.FlowMap(system(-0.05), h=1.0),
        "flow_section": hv.FlowMap(system(0.05), h=1.0, coordinates="section", stepper="rkck", max_impacts=50),
        "system_poly": hv.StepSystem(
            V1=hv.Tan(1.1, 0.4),
            V2=hv.Harmonic(1.3),
            coupling=hv.Polynomial({(1, 1): 1.0, (2, 1): -0.3}),
            eps=0.02,
            qw1=-0.9,
            qw2=-0.4,
            geometry="wall",
        ),
    }
    objects["curve"] = objects["flow_normal"].curve
    objects["section"] = objects["flow_normal"].section
    rng = np.random.default_rng(11)
    phi = rng.uniform(-np.pi, np.pi, 40)
    expected = {"phi": phi}
    bands = {
        "truncated": (-0.6, 0.6),
        "truncated_capped": (-0.3, 0.15),
        "family": (-0.5, 0.5),
        "flow_normal": (-0.1, 0.05),
        "flow_section": (0.25, 0.45),
    }
    for name, (lo, hi) in bands.items():
        K = rng.uniform(lo, hi, phi.size)
        p1, K1 = objects[name].step(phi, K)
        expected[f"{name}.K"], expected[f"{name}.phi1"], expected[f"{name}.K1"] = K, p1, K1
    h = hv.hovering_area(m, n_steps=200, n_samples=500, keep_points=True)
    objects["hovering_area"] = h
    for name, obj in objects.items():
        (OUT / f"{name}.pkl").write_bytes(pickle.dumps(obj, protocol=4))
        hv.save(obj, OUT / f"{name}.npz")
    np.savez(OUT / "expected.npz", **expected)
    print("hovering", hv.__version__, "wrote", sorted(objects))


if __name__ == "__main__":
    main()
