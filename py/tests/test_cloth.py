"""Paper 02 (cloth with soft constraints) from Python: closed forms, energy behaviour,
meshes and bad input."""

import numpy as np
import pytest

from results_check import check_result
from wscg import cloth

H = 1.0 / 60.0


def test_alpha_beta_closed_form_on_a_link():
    # One 1 kg particle on a 100 N/m link (rest 1 m) to a pinned anchor, stretched 5 cm.
    m = cloth.particles([[0.0, 0, 0], [1.05, 0, 0]], [1.0, 1.0], pinned=[0])
    m.set_gravity((0.0, 0.0, 0.0))
    m.add_link(0, 1, 100.0, rest=1.0)
    w2 = 100.0
    for ab in (1.0, 0.6, 0.5):
        sim = cloth.Sim(m, alpha=ab, beta=ab, n_iter=5)
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
        e0 = sim.energy().total
        energies = sim.step(H, 300)
        assert energies.shape == (300, 4)
        assert np.allclose(energies[:, 3], energies[:, :3].sum(axis=1))
        # The energy of the state is the last row of the step's energies, in its order.
        e = sim.energy()
        check_result(e, cloth.Energy)
        np.testing.assert_allclose(e, energies[-1], rtol=1e-12, atol=1e-15)
        assert e.total == pytest.approx(e.kinetic + e.gravity + e.elastic)
        assert sim.model().energy() == pytest.approx(e)
        losses[ab] = e0 - energies[-1, 3]
    assert losses[0.6] < losses[1.0]
    for method, opts in [("pbd", {"stiffness": 0.5}), ("symplectic", {"n_substeps": 8}),
                         ("ie_cg", {"tol": 1e-13})]:
        sim = cloth.Sim(m, method=method, n_iter=10, **opts)
        sim.step(H, 3)
        assert np.all(np.isfinite(sim.positions)) and sim.n_steps == 3
    # The linearised step by sparse Cholesky equals the CG solve.
    direct = cloth.Sim(m, method="ie_direct")
    direct.step(H, 3)
    np.testing.assert_allclose(direct.positions, sim.positions, atol=1e-10)
    # Three routes to the exact implicit Euler step land on the same state: Newton's
    # minimiser, the global constraint solve with the momentum residual, and NCG.
    stiff = cloth.grid(6, 6, mass=0.1, k_stretch=500.0, k_shear=500.0)
    states = {}
    for method, it in [("ie_newton", 1), ("global_cr", 40), ("ncg", 400)]:
        sim = cloth.Sim(stiff, method=method, n_iter=it)
        sim.step(H, 3)
        states[method] = sim.positions
    for method in ("global_cr", "ncg"):
        np.testing.assert_allclose(states[method], states["ie_newton"], atol=1e-8)
    # The regularized projection (XPBD) reaches a different point; it is not exact IE.
    sim = cloth.Sim(stiff, n_iter=200)
    sim.step(H, 3)
    assert np.abs(sim.positions - states["ie_newton"]).max() > 1e-6
    # The model given to Sim is not modified.
    assert np.allclose(m.positions[:, 1], 0.0)


def test_fem_mesh_and_grid():
    m = cloth.grid(8, 8, model="fem", young=500.0, poisson=0.3)
    assert m.counts == (0, 2 * 7 * 7, 0)
    sim = cloth.Sim(m, n_iter=10)
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
        lambda: cloth.Sim(m, method="symplectic", n_substeps="many"),
        lambda: cloth.Sim(m, relaxation="chebyshev"),
        lambda: cloth.Sim(m, relaxation="jacobi", omega=1.5),
        lambda: cloth.Sim(m, relaxation="sor", omega=2.0),
        lambda: cloth.sphere((0, 0, 0), -1.0),
        lambda: cloth.sphere((0, np.nan, 0), 1.0),
        lambda: cloth.plane((0, 0, 0)),
        lambda: cloth.capsule((0, 0, 0), (1, 0, 0), 0.0),
        lambda: cloth.mesh_collider([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 5]]),
        lambda: cloth.Sim(m).set_collisions([cloth.plane((0, 1, 0))], thickness=0.0),
        lambda: cloth.Sim(m).set_collisions([], friction=-1.0),
        lambda: cloth.Sim(m, method="ncg").set_collisions([cloth.plane((0, 1, 0))]),
    ]
    for fn in bad:
        with pytest.raises(ValueError):
            fn()


def test_sweep_variants_agree_on_energy():
    """Gauss-Seidel, coloured Gauss-Seidel (parallel), SOR and Jacobi solve the same
    constraints: converged, their energies after a second of hanging agree to 1 % (the
    converged projection depends slightly on the visiting order); Jacobi needs far more
    sweeps, and with few it is visibly off."""
    m = cloth.grid(12, 12, k_stretch=500.0, k_shear=500.0)

    def total(relaxation, omega, iterations):
        sim = cloth.Sim(m, n_iter=iterations, relaxation=relaxation, omega=omega)
        return sim.step(H, 60)[-1, 3]

    ref = total("gauss_seidel", None, 200)
    for relaxation, omega, iterations in [("colored", None, 200), ("sor", 1.3, 200),
                                          ("jacobi", 0.15, 3000)]:
        e = total(relaxation, omega, iterations)
        assert abs(e - ref) < 1e-2 * abs(ref), (relaxation, e, ref)
    assert abs(total("jacobi", 0.15, 200) - ref) > 0.05 * abs(ref)


def _uv_sphere(r, n=48):
    th = np.linspace(0, np.pi, n + 1)
    ph = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = [[0, 0, r]] + [[r * np.sin(t) * np.cos(p), r * np.sin(t) * np.sin(p), r * np.cos(t)]
                       for t in th[1:-1] for p in ph] + [[0, 0, -r]]
    ring = lambda i, j: 1 + i * n + (j % n)  # noqa: E731
    f = [[0, ring(0, j), ring(0, j + 1)] for j in range(n)]
    for i in range(n - 2):
        for j in range(n):
            f += [[ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)],
                  [ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]]
    last = len(v) - 1
    f += [[last, ring(n - 2, j + 1), ring(n - 2, j)] for j in range(n)]
    return np.array(v), np.array(f)


def test_collisions_sphere_mesh_and_friction():
    r, th = 0.3, 0.005
    v, f = _uv_sphere(r)
    mesh = cloth.mesh_collider(v, f)
    ball = cloth.sphere((0, 0, 0), r)
    p = np.random.default_rng(0).uniform(-0.6, 0.6, (300, 3))
    sag = r * (1 - np.cos(np.pi / 48) ** 2) + 1e-5
    np.testing.assert_allclose(mesh.signed_distance(p), ball.signed_distance(p), atol=sag)
    np.testing.assert_allclose(ball.signed_distance(p), np.linalg.norm(p, axis=1) - r,
                               atol=1e-12)
    # A cloth hanging from two corners swings onto a ball without entering it.
    c = np.array([0.5, -0.4, 0.5])
    grid = cloth.grid(15, 15, k_stretch=2000.0, k_shear=2000.0, k_bend=200.0)
    def closest(collide):
        sim = cloth.Sim(grid)
        if collide:
            sim.set_collisions([cloth.sphere(c, r)], thickness=th, friction=0.5)
        d = np.inf
        for _ in range(90):
            sim.step(H)
            d = min(d, np.linalg.norm(sim.positions - c, axis=1).min())
        return d

    assert closest(True) >= r + th - 1e-9
    assert closest(False) < r  # without contacts it swings through the ball


def test_friction_on_an_incline_matches_coulomb():
    theta = np.radians(20.0)
    n = np.array([-np.sin(theta), np.cos(theta), 0.0])
    down = np.array([np.cos(theta), np.sin(theta), 0.0])
    th = 0.01
    slid = {}
    for mu in (0.1, 0.5):
        sim = cloth.Sim(cloth.particles([n * th], [0.01]))
        sim.set_collisions([cloth.plane(n)], thickness=th, friction=mu)
        sim.step(H, 60)
        slid[mu] = float((n * th - sim.positions[0]) @ down)
    a = 9.81 * (np.sin(theta) - 0.1 * np.cos(theta))
    assert slid[0.1] == pytest.approx(a * H * H * 60 * 61 / 2, rel=1e-9)
    assert abs(slid[0.5]) < 1e-12


def test_roller_forces_carry_a_chain_resting_on_a_ramp():
    # Three 0.2 kg particles linked in a row along x, lying on rollers on the plane through
    # the x axis tilted by 0.3 rad: each reaction is m g cos(0.3) for every roller method.
    t = 0.3
    pos = [[0.1 * i, 0.0, 0.0] for i in range(3)]
    for method in ("soft", "ie_cg", "ie_direct", "ie_newton", "global_cr"):
        m = cloth.particles(pos, [0.2] * 3)
        for i in range(2):
            m.add_link(i, i + 1, 300.0)
        for i in range(3):
            m.add_roller(i, (0.0, np.cos(t), np.sin(t)), 0.0)
        sim = cloth.Sim(m, method=method)
        sim.step(H, 20)
        assert sim.roller_forces == pytest.approx([0.2 * 9.81 * np.cos(t)] * 3, rel=1e-6)
        assert np.allclose(sim.multipliers[-3:], sim.roller_forces)
        # The particles stay on their plane.
        assert np.abs(sim.positions @ np.array([0.0, np.cos(t), np.sin(t)])).max() < 1e-9
    # A particle off its plane is refused by the velocity-filter methods, by name.
    m = cloth.particles(pos, [0.2] * 3)
    m.add_roller(1, (0.0, 1.0, 0.0), 0.05)
    with pytest.raises(ValueError, match="particle 1"):
        cloth.Sim(m, method="ie_cg").step(H)
