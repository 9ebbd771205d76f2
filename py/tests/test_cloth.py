"""Paper 02 (cloth with soft constraints) from Python: closed forms, energy behaviour,
meshes and bad input."""

import numpy as np
import pytest

from wscg import cloth

H = 1.0 / 60.0


def test_alpha_beta_closed_form_on_a_link():
    # One 1 kg particle on a 100 N/m link (rest 1 m) to a pinned anchor, stretched 5 cm.
    m = cloth.particles([[0.0, 0, 0], [1.05, 0, 0]], [1.0, 1.0], pinned=[0])
    m.set_gravity((0.0, 0.0, 0.0))
    m.add_link(0, 1, 100.0, rest=1.0)
    w2 = 100.0
    for ab in (1.0, 0.6, 0.5):
        sim = cloth.Sim(m, alpha=ab, beta=ab, iterations=5)
        x, v = 0.05, 0.0
        for _ in range(200):
            xn = ((1 - H * H * ab * (1 - ab) * w2) * x + H * v) / (1 + H * H * ab * ab * w2)
            v = v - H * w2 * ((1 - ab) * x + ab * xn)
            x = xn
        sim.step(H, 200)
        assert sim.positions[1, 0] - 1.0 == pytest.approx(x, abs=1e-12)
        assert sim.velocities[1, 0] == pytest.approx(v, abs=1e-10)


def test_energy_behaviour_and_methods():
    m = cloth.grid(10, 10, mass=0.1, k_stretch=2.0, k_shear=2.0, k_bend=2.0)
    losses = {}
    for ab in (0.6, 1.0):
        sim = cloth.Sim(m, alpha=ab, beta=ab)
        e0 = sim.energy()["total"]
        energies = sim.step(H, 300)
        assert energies.shape == (300, 4)
        assert np.allclose(energies[:, 3], energies[:, :3].sum(axis=1))
        losses[ab] = e0 - energies[-1, 3]
    assert losses[0.6] < losses[1.0]
    for method, opts in [("pbd", {"stiffness": 0.5}), ("symplectic", {"substeps": 8}),
                         ("ie_cg", {})]:
        sim = cloth.Sim(m, method=method, iterations=10, **opts)
        sim.step(H, 3)
        assert np.all(np.isfinite(sim.positions)) and sim.steps == 3
    # Three routes to the exact implicit Euler step land on the same state: Newton's
    # minimiser, the global constraint solve with the momentum residual, and NCG.
    stiff = cloth.grid(6, 6, mass=0.1, k_stretch=500.0, k_shear=500.0)
    states = {}
    for method, it in [("ie_newton", 1), ("global_cr", 40), ("ncg", 400)]:
        sim = cloth.Sim(stiff, method=method, iterations=it)
        sim.step(H, 3)
        states[method] = sim.positions
    for method in ("global_cr", "ncg"):
        np.testing.assert_allclose(states[method], states["ie_newton"], atol=1e-8)
    # The regularized projection (XPBD) reaches a different point; it is not exact IE.
    sim = cloth.Sim(stiff, iterations=200)
    sim.step(H, 3)
    assert np.abs(sim.positions - states["ie_newton"]).max() > 1e-6
    # The model given to Sim is not modified.
    assert np.allclose(m.positions[:, 1], 0.0)


def test_fem_mesh_and_grid():
    m = cloth.grid(8, 8, model="fem", young=500.0, poisson=0.3)
    assert m.counts == (0, 2 * 7 * 7, 0)
    sim = cloth.Sim(m, iterations=10)
    sim.step(H, 30)
    assert sim.positions[:, 1].min() < -0.05
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    mesh = cloth.from_mesh(v, f, mass=0.2, model="links", k_edge=100.0, k_bend=1.0,
                           pinned=[0])
    assert mesh.counts == (6, 0, 0)  # 5 edges + 1 bending link across the diagonal
    # Area lumping: vertices 0 and 2 touch both triangles (1/3 of the area), 1 and 3 one.
    assert mesh.inv_mass[0] == 0.0
    np.testing.assert_allclose(1.0 / mesh.inv_mass[1:], [0.2 / 6, 0.2 / 3, 0.2 / 6])


def test_bad_input():
    m = cloth.grid(4, 4)
    bad = [
        lambda: cloth.Sim(m, alpha=0.0),
        lambda: cloth.Sim(m, beta=1.5),
        lambda: cloth.Sim(m, gamma=-1.0),
        lambda: cloth.Sim(m, method="explicit"),
        lambda: cloth.Sim(m, lambda_mode="reset"),
        lambda: cloth.Sim(m).step(0.0),
        lambda: cloth.Sim(m).step(float("nan")),
        lambda: cloth.grid(1, 4),
        lambda: cloth.grid(4, 4, model="springs"),
        lambda: cloth.from_mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]]),
        lambda: cloth.from_mesh([[0, 0, 0], [1, 0, 0]], [[0, 1, 2]]),
        lambda: cloth.from_mesh([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]),
        lambda: cloth.from_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], mass=-1.0),
        lambda: cloth.from_mesh(np.zeros((3, 2)), [[0, 1, 2]]),
        lambda: m.pin([100]),
        lambda: m.add_link(0, 0, 1.0),
        lambda: m.set_velocities(np.zeros((3, 3))),
        lambda: cloth.particles([[0, 0, 0]], [-1.0]),
        lambda: cloth.particles([[0, 0, 0]], [1.0, 2.0]),
        lambda: cloth.Sim(m, method="symplectic", substeps="many"),
    ]
    for fn in bad:
        with pytest.raises(ValueError):
            fn()
