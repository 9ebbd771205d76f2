"""Paper 10 (the unified triangle/voxel octree): wscg.octree against Embree 4 through
``embreex``, the triangle ray-casting library a user would otherwise pick.

Workload (spec section 5): the forest scene (13 procedural trees, about 1.4 M triangles),
L = 9, 1024 x 1024 primary rays of a pinhole camera (45 degrees) at a far view (the scene
spans about 300 pixels, 4 cube sides away) and a near view (0.7 cube sides), 2 threads.

- build: ``octree.build`` (voxelization + early-stop octree) against the Embree scene
  construction and commit (a first query);
- ray casting: ``HybridOctree.intersect`` in ``"triangles"`` mode (exact, target: at most 4x
  Embree's time), the same without shading (``shading=False``: ``t``, triangle and level,
  what Embree's ``run`` returns) and ``"hybrid"`` mode (LoD with the camera's footprint) against
  ``EmbreeScene.run`` on the same rays; the triangle answers' agreement with Embree's is
  printed.
"""

import os
import sys

import numpy as np

from wscg import octree

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

RES = 1024
FOV = 45.0


def camera_rays(eye, target, up=(0.0, 0.0, 1.0)):
    """Unit primary rays through the pixel centres (row 0 at the top), as wscg's camera."""
    eye, target, up = (np.asarray(x, dtype=np.float64) for x in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    h = np.tan(np.radians(FOV) / 2)
    x = (2 * (np.arange(RES) + 0.5) / RES - 1) * h
    y = (1 - 2 * (np.arange(RES) + 0.5) / RES) * h
    d = f[None, None, :] + x[None, :, None] * r + y[:, None, None] * u
    d = d.reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.broadcast_to(eye, d.shape)
    return np.ascontiguousarray(o, dtype=np.float32), np.ascontiguousarray(d, dtype=np.float32)


v, f, c = octree.make_scene("forest")
print(f"forest: {len(f)} triangles, L = 9, {RES}x{RES} primary rays")
rows = []
t_build = best_time(lambda: octree.build(v, f, c, depth=9), repeat=3)
tree = octree.build(v, f, c, depth=9)
(mn, side) = tree.cube
centre = np.asarray(mn) + side / 2
spread = 2 * np.tan(np.radians(FOV) / 2) / RES

try:
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh
except ImportError as e:  # pragma: no cover
    print(f"embreex could not run: {e}")
    sys.exit(0)

tri = np.ascontiguousarray(v[f].astype(np.float32))
one_o = np.zeros((1, 3), np.float32)
one_d = np.ones((1, 3), np.float32)


def embree_build():
    es = rtcs.EmbreeScene()
    TriangleMesh(es, tri)
    es.run(one_o, one_d)
    return es


t_eb = best_time(embree_build, repeat=3)
rows.append(("build (forest, L = 9)", t_build, "Embree scene + commit", t_eb))
es = embree_build()

for label, dist in [("far view (4 S)", 4.0), ("near view (0.7 S)", 0.7)]:
    a = 0.6
    eye = centre + side * dist * np.array([np.cos(a), np.sin(a), 0.3])
    o, d = camera_rays(eye, centre)
    t_tri = best_time(lambda: tree.intersect(o, d, mode="triangles"), repeat=3)
    t_cast = best_time(lambda: tree.intersect(o, d, mode="triangles", shading=False), repeat=3)
    t_hyb = best_time(lambda: tree.intersect(o, d, mode="hybrid", footprint_spread=spread),
                      repeat=3)
    t_em = best_time(lambda: es.run(o, d, output=1), repeat=3)
    ours = tree.intersect(o, d, mode="triangles")
    theirs = es.run(o, d, output=1)
    pe = np.asarray(theirs["primID"]).astype(np.int64)
    pe[pe == 2**32 - 1] = -1
    hit_o, hit_e = ours.prim >= 0, pe >= 0
    both = hit_o & hit_e
    same = np.mean(ours.prim[both] == pe[both]) if both.any() else float("nan")
    print(f"{label}: hits ours {hit_o.sum()}, Embree {hit_e.sum()}, hit/miss agreement "
          f"{np.mean(hit_o == hit_e):.5f}, same triangle on {same:.5f} of common hits")
    rows.append((f"{label} triangles", t_tri, "embreex run (primary)", t_em))
    rows.append((f"{label} triangles, no shading", t_cast, "embreex run (primary)", t_em))
    rows.append((f"{label} hybrid (LoD)", t_hyb, "embreex run (primary)", t_em))

print_table("Paper 10: ours (wscg) against Embree; ratio = peer / ours", rows)
