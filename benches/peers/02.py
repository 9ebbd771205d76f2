"""Paper 02 (cloth with soft constraints): wscg.cloth against pyPBD (J. Bender's
PositionBasedDynamics, PyPI ``pyPBD`` 2.2.2) on the same hanging cloth.

Scene (spec section 5): a 40 x 40 particle cloth, 1 m x 1 m in the x-z plane, total mass 0.1 kg,
hanging from the two corners of its first row (particles 0 and 39), gravity 9.81 m/s^2 along
-y, h = 1/60 s, 25 iterations, one substep, no damping, 600 steps (10 s) from rest. Both
libraries get the same particle positions and masses (pyPBD's masses are set from ours).
The table gives seconds for the 600 steps (median of 3 runs; a run includes building our
``Sim`` or resetting pyPBD's model, under 1 ms), and the lines below it ms per step.

Workloads:
- links: ours ``grid(k_stretch=k_shear=k_bend=2000 N/m)`` (structural links, shear links on
  both diagonals and bending links two particles apart: 9202 links), soft projection with
  accumulated multipliers (XPBD-equivalent) and sequential Gauss-Seidel, one thread; peer
  ``addClothConstraints`` method 4 (XPBD distance constraints, k = 2000 N/m, on the 4641
  triangle edges: structural plus one alternating diagonal per quad) and
  ``addBendingConstraints`` method 3 (XPBD isometric bending on the 4485 interior edges),
  9126 constraints. Extra row: ours with graph-coloured Gauss-Seidel on all threads (the
  peer is still single-threaded).
- FEM: ours ``from_mesh`` on pyPBD's own triangles (3042 StVK membrane triangles,
  young = 1000 N/m, poisson = 0.3) plus bending links of 50 N/m across the 4485 interior
  edges, sequential Gauss-Seidel, one thread; peer method 2 (PBD FEM triangle, Bender et al.
  2014) with youngs xx = yy = 1000, shear xy = 1000 / 1.3 (2 mu of the isotropic material),
  Poisson ratios 0.3, plus the same isometric bending.

Units differ between the libraries:
- pyPBD's XPBD distance stiffness is in N/m with compliance 1/(k h^2), as our links.
- pyPBD's FEM triangle is plain PBD: each projection removes the triangle's whole energy, so
  only the ratios of the moduli matter (E = 1 and E = 1000 give the same motion) and its
  stiffness grows with the iteration count; ours is a soft constraint with E in N/m.
- pyPBD's XPBD isometric bending constrains C = x^T Q x / 2 (dimensionless) with stiffness in J.
  A fold of angle t across one structural edge (a = 1/39 m) costs k a^2 t^4 / 32 with our
  bending link and k_pbd (0.75 t^2)^2 / 2 with pyPBD's, so k_pbd = k a^2 / 9 (0.146 J for
  2000 N/m, 3.7e-3 J for 50 N/m).

pyPBD runs with OMP_NUM_THREADS=1. Our ``Sim.step(h, n)`` also evaluates the energies after
every step; that is included in our times.
"""

import os
import sys
from importlib.metadata import version

os.environ["OMP_NUM_THREADS"] = "1"  # before pypbd loads its OpenMP runtime

import numpy as np  # noqa: E402
import pypbd as pbd  # noqa: E402

from wscg import cloth  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

N = 40  # particles per side
SIZE = 1.0  # metres
MASS = 0.1  # kg
H = 1.0 / 60.0
ITER = 25
STEPS = 600
K = 2000.0  # N/m: stretch and shear links, pyPBD's XPBD distance constraints
K_BEND = 2000.0  # N/m: bending links of the link cloth
K_BEND_FEM = 50.0  # N/m: bending links of the FEM cloth
YOUNG, NU = 1000.0, 0.3  # N/m, Poisson ratio of the membrane
A = SIZE / (N - 1)


def k_bend_pbd(k):
    """pyPBD's XPBD isometric bending stiffness (J) with the fold energy of a link of k N/m."""
    return k * A * A / (16.0 * 0.75 ** 2)


# Rotates pyPBD's grid from the x-y plane, (x, y, 0) -> (x, 0, y): particle j * N + i lies at
# (i a, 0, j a) as in cloth.grid.
ROT = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
SIM = pbd.Simulation.getCurrent()
SIM.initDefault()  # TimeStepController, gravity (0, -9.81, 0), SDF collision detection


def pbd_cloth(method, stiffness, k_bend):
    """Builds the peer cloth (replacing any previous one) and returns (model, particles,
    faces). ``method`` 4: XPBD distance constraints on the mesh edges; 2: PBD FEM
    triangles. Masses are left at pyPBD's default (1 kg) until :func:`pbd_set_masses`."""
    model = SIM.getModel()
    model.cleanup()
    tri = model.addRegularTriangleModel(N, N, [0.0, 0.0, 0.0], ROT, [SIZE, SIZE],
                                        testMesh=False)
    xx, yy, xy = stiffness
    model.addClothConstraints(tri, method, K, xx, yy, xy, NU, NU, False, False)
    model.addBendingConstraints(tri, 3, k_bend)
    ts = SIM.getTimeStep()
    # The parameter ids are class attributes filled in by initDefault (-1 before it).
    ts.setValueUInt(pbd.TimeStepController.MAX_ITERATIONS, ITER)
    ts.setValueUInt(pbd.TimeStepController.NUM_SUB_STEPS, 1)
    pbd.TimeManager.getCurrent().setTimeStepSize(H)
    mesh = tri.getParticleMesh()  # keep it alive: getFaces() is a view into it
    faces = np.array(mesh.getFaces(), dtype=np.int64).reshape(-1, 3)
    return model, model.getParticles(), faces


def pbd_set_masses(pd, ours):
    for i, w in enumerate(ours.inv_mass):
        pd.setMass(i, 1.0 / w if w > 0.0 else 0.0)  # mass 0 pins the particle


def pbd_run(model, pd, out, key):
    ts, tm = SIM.getTimeStep(), pbd.TimeManager.getCurrent()

    def run():
        model.reset()  # positions to rest, velocities zero, constraints updated
        tm.setTime(0.0)
        for _ in range(STEPS):
            ts.step(model)
        out[key] = float(np.array(pd.getVertices())[:, 1].min())
    return run


def ours_run(model, out, key, relaxation="gauss_seidel"):
    def run():
        sim = cloth.Sim(model, method="soft", n_iter=ITER, relaxation=relaxation)
        sim.step(H, STEPS)
        out[key] = float(sim.positions[:, 1].min())
    return run


lowest = {}
rows = []
threads = len(os.sched_getaffinity(0))

# Link cloth.
links = cloth.grid(N, N, (SIZE, SIZE), MASS, model="links", k_stretch=K, k_shear=K,
                   k_bend=K_BEND)
pmodel, pd, _ = pbd_cloth(4, (K, K, K), k_bend_pbd(K_BEND))
pbd_set_masses(pd, links)
assert np.allclose(np.array(pd.getVertices()), links.positions, atol=1e-12)
n_pbd_links = len(pmodel.getConstraints())
t_pbd = best_time(pbd_run(pmodel, pd, lowest, "pyPBD links"), repeat=3)
rows.append((f"40x40 links GS 1 thr, {STEPS} steps",
             best_time(ours_run(links, lowest, "ours links GS"), repeat=3),
             "pyPBD XPBD dist+bend 1 thr", t_pbd))
rows.append((f"40x40 links colored {threads} thr, {STEPS} steps",
             best_time(ours_run(links, lowest, "ours links colored", "colored"), repeat=3),
             "pyPBD XPBD dist+bend 1 thr", t_pbd))

# FEM membrane on pyPBD's triangles (alternating diagonals).
pmodel, pd, faces = pbd_cloth(2, (YOUNG, YOUNG, YOUNG / (1.0 + NU)), k_bend_pbd(K_BEND_FEM))
fem = cloth.from_mesh(np.array(pd.getVertices()), faces, MASS, model="fem", young=YOUNG,
                      poisson=NU, k_bend=K_BEND_FEM, pinned=[0, N - 1])
assert fem.counts[0] > 0, "this wscg build has no bending links on FEM meshes: rebuild it"
pbd_set_masses(pd, fem)
n_pbd_fem = len(pmodel.getConstraints())
rows.append((f"40x40 FEM+bend GS 1 thr, {STEPS} steps",
             best_time(ours_run(fem, lowest, "ours FEM GS"), repeat=3),
             "pyPBD FEM tri+bend 1 thr",
             best_time(pbd_run(pmodel, pd, lowest, "pyPBD FEM"), repeat=3)))

print_table(f"paper 02: wscg.cloth vs pyPBD {version('pyPBD')} (seconds for {STEPS} steps of "
            f"1/60 s, {ITER} iterations)", rows)
print()
for workload, ours, peer_name, peer in rows:
    print(f"{workload:<36} ours {1e3 * ours / STEPS:6.2f} ms/step, "
          f"{peer_name} {1e3 * peer / STEPS:6.2f} ms/step")
print(f"constraints: links ours {links.counts[0]} links, pyPBD {n_pbd_links}; "
      f"FEM ours {fem.counts[1]} triangles + {fem.counts[0]} links, pyPBD {n_pbd_fem}")
print(f"lowest y after {STEPS * H:g} s (m; the cloth starts at y = 0 and swings): "
      + ", ".join(f"{k} {v:.3f}" for k, v in lowest.items()))
