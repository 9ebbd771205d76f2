"""Joint bilateral mesh denoising (paper 04) written directly with numpy and scipy's cKDTree:
the reference that pytest compares wscg.meshfilter.jbmd with, and the numpy peer of
benches/peers/04.py."""

import numpy as np
from scipy.spatial import cKDTree


def normals(v, f):
    """Area-weighted unit vertex normals."""
    c = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for k in range(3):
        np.add.at(n, f[:, k], c)
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)


def boundary(v, f):
    """Mask of the vertices on a boundary edge (an edge of one face)."""
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    b = np.zeros(len(v), bool)
    b[uniq[count == 1].ravel()] = True
    return b


def reference_jbmd(v, f, c, sd, so, sc, lam, k, iters):
    """The JBMD algorithm as the library implements it, written with numpy and cKDTree."""
    v = v.copy()
    fixed = boundary(v, f)
    g = lambda t, s: np.exp(-0.5 * (t / s) ** 2)  # noqa: E731
    for _ in range(iters):
        n = normals(v, f)
        _, nb = cKDTree(v).query(v, k + 1)
        nb = nb[:, 1:]  # drop the vertex itself (no duplicate points in these meshes)
        d = v[nb] - v[:, None, :]
        o = np.einsum("ij,ikj->ik", n, d)
        w = g(np.linalg.norm(d, axis=2), sd) * g(o, so)
        if c is not None:
            w *= g(np.linalg.norm(c[nb] - c[:, None, :], axis=2), sc)
        x1 = (w * o).sum(1) / w.sum(1)
        x1[fixed] = 0
        v1 = v + x1[:, None] * n
        w2 = g(np.linalg.norm(v1[nb] - v1[:, None, :], axis=2), sd)
        x2 = (w2 * x1[nb]).sum(1) / w2.sum(1)
        x2[fixed] = 0
        v = v1 - x2[:, None] * n
        so *= lam
    return v
