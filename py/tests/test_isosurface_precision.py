"""float64 volumes are extracted in double precision: an exactly linear field with anisotropic
spacing gives its exact normal with every estimator (each is exact for a linear field)."""

import numpy as np
import pytest

from wscg import isosurface

A = np.array([0.37, -0.81, 1.13])  # (ax, ay, az), world units
SPACING = (0.45, 1.3, 0.7)  # (dz, dy, dx)


def _linear(dtype):
    z, y, x = np.mgrid[:27, :19, :23].astype(np.float64)
    vol = A[0] * x * SPACING[2] + A[1] * y * SPACING[1] + A[2] * z * SPACING[0] + 1.9
    return vol.astype(dtype)


@pytest.mark.parametrize("method", ["lsn", "spline", "central"])
def test_linear_field_normals_exact_in_float64(method):
    v, f, n, info = isosurface.marching_cubes(_linear(np.float64), 0.0, spacing=SPACING,
                                              normals=method, origin=(1.0, -2.0, 0.5))
    assert v.dtype == np.float64 and n.dtype == np.float64
    assert len(v) > 500 and info.n_undefined == 0
    want = A / np.linalg.norm(A)
    assert np.abs(n - want).max() < 1e-9
    # Vertices on the plane a . (p - origin) = -1.9 (world units, origin (ox, oy, oz)).
    o = np.array([0.5, -2.0, 1.0])
    assert np.abs((v - o) @ A + 1.9).max() < 1e-12
    n2, _ = isosurface.estimate_normals(_linear(np.float64), 0.0, info.edges, spacing=SPACING,
                                        normals=method)
    assert n2.dtype == np.float64 and np.abs(n2 - want).max() < 1e-9


def test_float32_stays_float32():
    v, f, n, info = isosurface.marching_cubes(_linear(np.float32), 0.0, spacing=SPACING,
                                              normals="lsn")
    assert v.dtype == np.float32 and n.dtype == np.float32
    # Single precision: far from 1e-9, which the float64 path reaches.
    err = np.abs(n.astype(np.float64) - A / np.linalg.norm(A)).max()
    assert 1e-7 < err < 1e-2
    sparse, inside = isosurface.sparsify(_linear(np.float64), 0.0)
    assert sparse.dtype == np.float64
    assert isosurface.random_dropouts(_linear(np.float32), 0.1).dtype == np.float32
