from typing import Any, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

__all__: list[str]

class Model:
    positions: F64
    velocities: F64
    inv_mass: F64
    counts: Tuple[int, int, int]
    def set_velocities(self, v: npt.ArrayLike) -> None: ...
    def pin(self, indices: Sequence[int]) -> None: ...
    def set_gravity(self, g: Tuple[float, float, float]) -> None: ...
    def add_link(self, i: int, j: int, k: float, rest: Optional[float] = None) -> None: ...
    def add_roller(self, p: int, normal: Tuple[float, float, float], offset: float) -> None: ...
    def energy(self) -> dict[str, float]: ...

def particles(positions: npt.ArrayLike, masses: npt.ArrayLike,
              pinned: Optional[Sequence[int]] = None) -> Model: ...
def grid(nx: int, ny: int, size: Tuple[float, float] = (1.0, 1.0), mass: float = 0.1,
         model: str = "links", k_stretch: float = 2000.0, k_shear: Optional[float] = None,
         k_bend: Optional[float] = None, young: float = 1000.0, poisson: float = 0.3,
         pinned: Optional[Sequence[int]] = None) -> Model: ...
def from_mesh(vertices: npt.ArrayLike, faces: npt.ArrayLike, mass: float = 0.1,
              model: str = "fem", young: float = 1000.0, poisson: float = 0.3,
              k_edge: float = 2000.0, k_bend: Optional[float] = None,
              pinned: Optional[Sequence[int]] = None) -> Model: ...

class Sim:
    positions: F64
    velocities: F64
    multipliers: F64
    steps: int
    def __init__(self, model: Model, method: str = "soft", iterations: int = 25,
                 alpha: float = 1.0, beta: float = 1.0, gamma: float = 0.0,
                 lambda_mode: str = "accumulate", velocity_damping: float = 0.0,
                 relaxation: str = "gauss_seidel", omega: Optional[float] = None,
                 **options: Any) -> None: ...
    def step(self, h: float = ..., n: int = 1) -> F64: ...
    def energy(self) -> dict[str, float]: ...
    def model(self) -> Model: ...
