"""Cloth simulation with soft constraints: paper 02 of WSCG vol. 23 (Francu and
Moldoveanu, "Cloth Simulation Using Soft Constraints").

Implicit Euler on stiff springs equals the projection of *regularized* constraints
``c(x) + eps * lambda = 0`` (``eps = 1/k``). On that result the library offers:

- ``method="soft"``: soft-constraint projection with the paper's ``alpha``/``beta`` scheme
  (``1, 1``: implicit Euler / regularized PBD; towards ``0.5``: less energy loss) and its
  damping ``gamma`` (seconds) along the constraint directions;
- ``"ncg"``: the paper's nonlinear conjugate gradient implicit solver (``"ncg_paper"``: the
  residual as printed);
- ``"global_cr"``: global constraint-space solves by Conjugate Residuals (exact implicit
  Euler with the momentum residual);
- baselines ``"pbd"`` (plain position-based dynamics, option ``stiffness``),
  ``"symplectic"`` (explicit, option ``n_substeps``), ``"ie_cg"`` (one linearised implicit
  Euler step by CG), ``"ie_direct"`` (the same step by sparse Cholesky) and ``"ie_newton"`` (exact implicit Euler by Newton's method);
- membrane triangles with StVK elasticity (Young's modulus in N/m, Poisson ratio) as soft
  constraints (``model="fem"``), or link networks (``model="links"``);
- collisions (``Sim.set_collisions``) with :func:`plane`, :func:`sphere`, :func:`capsule`
  and closed triangle meshes (:func:`mesh_collider`), Coulomb friction and self contacts,
  solved in the projection loop of ``"soft"`` and ``"pbd"``.

Units: metres, kilograms, seconds; stiffness in N/m. Positions and velocities are
``(n, 3)`` float64 arrays. Bad arguments raise ``ValueError``; a diverging step raises
``ValueError`` and leaves the state unchanged.
"""

from __future__ import annotations

from typing import NamedTuple, Optional, Sequence

import numpy as np

from ._native import cloth as _c
from ._native.cloth import (Collider, Model, capsule, from_mesh, grid, mesh_collider,
                            particles, plane, sphere)
from ._checks import integer_ranges as _integer_ranges
from ._results import tuple_repr as _tuple_repr

__all__ = ["Model", "Sim", "Collider", "particles", "grid", "from_mesh", "plane", "sphere",
           "capsule", "mesh_collider", "Energy"]


class Energy(NamedTuple):
    """The energies of a state (``Model.energy()``, :meth:`Sim.energy`), a named tuple in the
    order of the rows of :meth:`Sim.step` (``kinetic, gravity, elastic, total =
    sim.energy()`` unpacks it).

    Attributes
    ----------
    kinetic : float
        ``sum 1/2 m |v|^2`` over the free particles, joules.
    gravity : float
        Gravitational potential ``-sum m g . x`` over the free particles, joules.
    elastic : float
        ``sum 1/2 c^2 / eps`` over the soft links plus the StVK energy of the membrane
        triangles, joules.
    total : float
        The sum of the three, joules.
    """

    kinetic: float
    gravity: float
    elastic: float
    total: float

    __repr__ = _tuple_repr


class Sim:
    """A cloth simulation.

    Parameters
    ----------
    model : Model
        From :func:`grid` or :func:`from_mesh` (copied; the model is not modified).
    method : str, default "soft"
        See the module documentation.
    n_iter : int, default 25
        Gauss-Seidel sweeps (soft, pbd), NCG iterations or global CR outer iterations per
        step (a fixed count, >= 1).
    alpha, beta : float in (0, 1], default 1
        The paper's blending of forces and positions (soft projection).
    gamma : float >= 0, default 0
        Constraint damping ``d/k`` in seconds.
    lambda_mode : {"accumulate", "paper"}, default "accumulate"
        ``"accumulate"`` keeps the multipliers over the iterations (stiffness independent of
        the iteration count); ``"paper"`` resets them as the paper's printed equations do.
    velocity_damping : float in [0, 1], default 0
        The velocity-projection damping baseline.
    relaxation : {"gauss_seidel", "colored", "jacobi", "sor"}, default "gauss_seidel"
        How each sweep of the soft projection visits the constraints: sequential
        Gauss-Seidel in creation order, graph-coloured Gauss-Seidel (colour classes in
        parallel on all threads), Jacobi (stable for ``omega`` below about the inverse of the
        number of constraints at a particle; default 0.15) or SOR (``omega`` in (0, 2),
        default 1.5).
    omega : float, optional
        Relaxation factor of Jacobi and SOR.
    stiffness : float in (0, 1], default 1
        PBD stiffness (method ``"pbd"``).
    n_substeps : int, default 64
        Explicit substeps per step (method ``"symplectic"``, >= 1).
    tol : float, optional
        Relative tolerance: of the CG solve (``"ie_cg"``, default 1e-8), of Newton's
        gradient (``"ie_newton"``, default 1e-10) or of each CR solve (``"global_cr"``,
        default 1e-10).
    max_iter : int, default 1000
        Iteration cap of the CG solve (``"ie_cg"``).
    primal_residual : bool, default True
        Keep the momentum residual, so that ``"global_cr"`` is exact implicit Euler.

    Options of other methods than the chosen one are ignored.
    """

    def __init__(self, model: "Model", method: str = "soft", n_iter: int = 25,
                 alpha: float = 1.0, beta: float = 1.0, gamma: float = 0.0,
                 lambda_mode: str = "accumulate", velocity_damping: float = 0.0,
                 relaxation: str = "gauss_seidel", omega: Optional[float] = None, *,
                 stiffness: float = 1.0, n_substeps: int = 64, tol: Optional[float] = None,
                 max_iter: int = 1000, primal_residual: bool = True):
        # The options, read and checked by name by the native solver (None: its default).
        options = dict(relaxation=relaxation, omega=omega, stiffness=stiffness,
                       n_substeps=n_substeps, tol=tol, max_iter=max_iter,
                       primal_residual=primal_residual)
        self._sim = _c.Sim(model, method, n_iter, alpha, beta, gamma, lambda_mode,
                           velocity_damping, options)

    def set_collisions(self, colliders: Sequence["Collider"] = (), thickness: float = 0.005,
                       friction: float = 0.3, self_collision: bool = False) -> None:
        """Sets the obstacles (from :func:`plane`, :func:`sphere`, :func:`capsule`,
        :func:`mesh_collider`), the cloth ``thickness`` (m) kept from them and between
        layers, the Coulomb ``friction`` coefficient and whether particles that share no
        constraint repel each other (``self_collision``). Contacts are inequality
        constraints solved in the iteration loop (methods ``"soft"`` and ``"pbd"``)."""
        self._sim.set_collisions(colliders, thickness, friction, self_collision)

    def step(self, h: float = 1.0 / 60.0, n_steps: int = 1) -> np.ndarray:
        """Advances ``n_steps`` steps of ``h`` seconds; returns the energy after each step as
        an ``(n_steps, 4)`` array: kinetic, gravitational, elastic, total (J)."""
        return self._sim.step(h, n_steps)

    @property
    def positions(self) -> np.ndarray:
        """Particle positions ``(n, 3)``."""
        return self._sim.positions

    @property
    def velocities(self) -> np.ndarray:
        """Particle velocities ``(n, 3)``."""
        return self._sim.velocities

    @property
    def multipliers(self) -> np.ndarray:
        """Constraint multipliers of the last step (one per link, three per triangle, one
        per roller)."""
        return self._sim.multipliers

    @property
    def roller_forces(self) -> np.ndarray:
        """Reaction forces of the rollers in the last step (N along each roller's unit
        normal, in the order they were added): the soft projection's multipliers, the
        constraint force of the step for ``ie_cg`` and ``ie_direct`` (which enforce rollers
        by velocity filters and refuse a particle off its roller plane, naming it) and for
        ``ie_newton`` and ``global_cr`` (which start from the nearest point of the planes
        and eliminate the rollers by the same filters: the normal part of the momentum
        residual at convergence). At rest they balance gravity and the elastic forces."""
        return self._sim.roller_forces

    @property
    def n_steps(self) -> int:
        """Steps taken."""
        return self._sim.n_steps

    def energy(self) -> Energy:
        """Energies of the current state (J), an :class:`Energy`: kinetic, gravity,
        elastic, total."""
        return self._sim.energy()

    def model(self) -> "Model":
        """The current state as a :class:`Model`."""
        return self._sim.model()

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
