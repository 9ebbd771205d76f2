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


def reference_two_stage(v, f, c, sd, sn, sc, iters, normal_iters, vertex_iters):
    """The two-stage update (jbmd's default) written with numpy: a joint bilateral filter of
    the face normals over the faces sharing a vertex, then vertex steps onto the planes of
    every vertex's faces."""
    v = v.copy()
    fixed = boundary(v, f)
    vf = [[] for _ in range(len(v))]
    for i, t in enumerate(f):
        for a in t:
            vf[a].append(i)
    ring = [sorted(set(vf[t[0]]) | set(vf[t[1]]) | set(vf[t[2]])) for t in f]
    rf = np.repeat(np.arange(len(f)), [len(r) for r in ring])
    rg = np.concatenate(ring)
    wc = np.ones(len(rf))
    if c is not None:
        col = c[f].mean(axis=1)
        wc = np.exp(-0.5 * (np.linalg.norm(col[rf] - col[rg], axis=1) / sc) ** 2)
    for _ in range(iters):
        cr = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        area = 0.5 * np.linalg.norm(cr, axis=1)
        m = cr / np.linalg.norm(cr, axis=1, keepdims=True)
        cen = v[f].mean(axis=1)
        w0 = area[rg] * wc * np.exp(-0.5 * (np.linalg.norm(cen[rf] - cen[rg], axis=1) / sd) ** 2)
        for _ in range(normal_iters):
            w = w0 * np.exp(-0.5 * (np.linalg.norm(m[rf] - m[rg], axis=1) / sn) ** 2)
            acc = np.zeros_like(m)
            np.add.at(acc, rf, w[:, None] * m[rg])
            m = acc / np.linalg.norm(acc, axis=1, keepdims=True)
        for _ in range(vertex_iters):
            cen = v[f].mean(axis=1)
            step = np.zeros_like(v)
            count = np.zeros(len(v))
            for k in range(3):
                o = np.einsum("ij,ij->i", m, cen - v[f[:, k]])
                np.add.at(step, f[:, k], o[:, None] * m)
                np.add.at(count, f[:, k], 1)
            step[fixed] = 0
            v = v + step / np.maximum(count, 1)[:, None]
    return v
