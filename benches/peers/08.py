"""Paper 08 peer benchmark: shadow rays against Embree, and the many-light methods against
Mitsuba 3's path tracer.

1. Shadow-ray throughput: the colonnade at subdivision 20 (96 000 triangles), 1 000 000
   random segments between points of the hall's box; ours (``ManyLightScene.occluded``,
   binned-SAH BVH in f64, rayon over 2 threads) against Embree 4 through ``embreex``
   (``query='OCCLUDED'``, f32). The answers' agreement is printed.
2. Paper 08's Table 1 on the colonnade (Sponza stand-in) at 512 x 384, 1 % of the pixels as
   records, 16 samples per pixel: cache, render and total seconds and RMSE against the
   all-VPL reference for ``ic``, ``adaptive_uniform`` and ``adaptive`` (ic with the adaptive
   run's record count), then ``ic`` at equal time (more samples per pixel).
3. Mitsuba 3 ``path`` (``scalar_rgb``, max depth 4 = VPL bounces + 2) on the same Cornell box
   geometry, materials and camera: its relative MSE against its own converged render at the
   wall time of our adaptive render, next to ours against our all-VPL reference.
"""

import time

import numpy as np

from _common import best_time, print_table
from wscg import raytrace as rt


def shadow_rays():
    scene = rt.make_manylight_scene("colonnade", subdiv=20, width=64, height=48)
    tris = scene.triangle_vertices()
    lo = tris.reshape(-1, 3).min(axis=0) + 0.1
    hi = tris.reshape(-1, 3).max(axis=0) - 0.1
    rng = np.random.default_rng(0)
    n = 1_000_000
    a = lo + rng.random((n, 3)) * (hi - lo)
    b = lo + rng.random((n, 3)) * (hi - lo)
    ours = best_time(lambda: scene.occluded(a, b), repeat=3)
    hit_ours = scene.occluded(a, b)
    print(f"{scene.n_triangles} triangles, {n} segments, {hit_ours.mean():.3f} blocked (ours)")
    try:
        from embreex import rtcore_scene as rtcs
        from embreex.mesh_construction import TriangleMesh
    except ImportError as e:  # pragma: no cover
        print(f"embreex could not run: {e}")
        return
    es = rtcs.EmbreeScene()
    TriangleMesh(es, tris.astype(np.float32))
    d = b - a
    length = np.linalg.norm(d, axis=1)
    dirs = (d / length[:, None]).astype(np.float32)
    org = a.astype(np.float32)
    dist = length.astype(np.float32)

    def embree():
        return es.run(org, dirs, dists=dist, query="OCCLUDED")

    peer = best_time(embree, repeat=3)
    hit_peer = np.asarray(embree()) != -1
    print(f"agreement with Embree: {np.mean(hit_peer == hit_ours):.5f}")
    print_table("Shadow rays (1 M segments, colonnade 96k triangles)",
                [("occlusion queries", ours, "embreex OCCLUDED", peer)])
    print(f"rays/s: ours {n / ours / 1e6:.2f} M, Embree {n / peer / 1e6:.2f} M")


def table1():
    scene = rt.make_manylight_scene("colonnade", subdiv=1, width=512, height=384)
    kw = dict(n_vpl_paths=1400, spp=16, n_cache=1966)
    ref, st = rt.render_manylight(scene, "reference", **kw)
    print(f"colonnade 512 x 384, {st.n_vpls} VPLs, reference {st.render_seconds:.1f} s")
    print(f"{'method':<18} {'records':>8} {'cache s':>8} {'render s':>9} {'total s':>8} {'RMSE':>9}")
    rows = {}
    for method in ["adaptive", "adaptive_uniform", "ic"]:
        if method == "ic":
            kw = dict(kw, n_cache=rows["adaptive"][0])
        img, s = rt.render_manylight(scene, method, **kw)
        err = float(np.sqrt(np.mean((img.astype(np.float64) - ref) ** 2)))
        rows[method] = (s.n_records, s.cache_seconds, s.render_seconds, err)
        print(f"{method:<18} {s.n_records:>8} {s.cache_seconds:>8.2f} {s.render_seconds:>9.2f} "
              f"{s.cache_seconds + s.render_seconds:>8.2f} {err:>9.5f}")
    a, ic = rows["adaptive"], rows["ic"]
    print(f"RMSE adaptive / ic {a[3] / ic[3]:.3f}; total time adaptive / ic {(a[1] + a[2]) / (ic[1] + ic[2]):.3f}")
    # Equal time: importance caching gets the samples its render can take in the time the
    # adaptive method spends more on its cache.
    spp = max(16, int(round(16 * (a[1] + a[2] - ic[1]) / ic[2])))
    img, s = rt.render_manylight(scene, "ic", **dict(kw, spp=spp))
    err = float(np.sqrt(np.mean((img.astype(np.float64) - ref) ** 2)))
    total = s.cache_seconds + s.render_seconds
    print(f"equal time: ic at {spp} spp {total:.2f} s, RMSE {err:.5f}; adaptive / ic {a[3] / err:.3f}")


def mitsuba_cornell():
    try:
        import mitsuba as mi
        mi.set_variant("scalar_rgb")
    except Exception as e:  # pragma: no cover
        print(f"Mitsuba 3 could not run: {e}")
        return
    w, h = 128, 96
    scene = rt.make_manylight_scene("cornell", width=w, height=h)
    cam = scene.camera
    kw = dict(n_vpl_paths=1400, spp=16, n_cache=w * h // 100)
    ref, _ = rt.render_manylight(scene, "reference", **kw)
    t = time.perf_counter()
    img, _ = rt.render_manylight(scene, "adaptive", **kw)
    ours_s = time.perf_counter() - t
    rel = float(np.mean((img - ref) ** 2) / np.mean(ref ** 2))
    tris = scene.triangle_vertices()
    albedo = scene.triangle_albedo()
    emission = scene.triangle_emission()
    d = {"type": "scene", "integrator": {"type": "path", "max_depth": 4},
         "sensor": {"type": "perspective", "fov": cam["fov_deg"], "fov_axis": "y",
                    "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["target"],
                                                               up=cam["up"]),
                    "film": {"type": "hdrfilm", "width": w, "height": h,
                             "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                    "sampler": {"type": "independent", "sample_count": 4}}}
    groups = {}
    for i in range(len(tris)):
        groups.setdefault((tuple(albedo[i]), tuple(emission[i])), []).append(i)
    import tempfile, os
    tmp = tempfile.mkdtemp()
    for k, ((alb, emi), ids) in enumerate(groups.items()):
        v = tris[ids].reshape(-1, 3)
        path = os.path.join(tmp, f"m{k}.obj")
        with open(path, "w") as f:
            f.writelines(f"v {x} {y} {z}\n" for x, y, z in v)
            f.writelines(f"f {3 * j + 1} {3 * j + 2} {3 * j + 3}\n" for j in range(len(ids)))
        shape = {"type": "obj", "filename": path, "face_normals": True,
                 "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse",
                                                      "reflectance": {"type": "rgb", "value": list(alb)}}}}
        if max(emi) > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(emi)}}
        d[f"shape{k}"] = shape
    ms = mi.load_dict(d)
    t = time.perf_counter()
    conv = np.array(mi.render(ms, spp=1024, seed=1))
    conv_s = time.perf_counter() - t
    per_spp = conv_s / 1024
    spp = max(1, int(round(ours_s / per_spp)))
    t = time.perf_counter()
    quick = np.array(mi.render(ms, spp=spp, seed=2))
    quick_s = time.perf_counter() - t
    rel_m = float(np.mean((quick - conv) ** 2) / np.mean(conv ** 2))
    print(f"Cornell {w} x {h}: ours adaptive {ours_s:.3f} s, relative MSE {rel:.5f} (vs all-VPL reference); "
          f"Mitsuba path {spp} spp {quick_s:.3f} s, relative MSE {rel_m:.5f} (vs its 1024 spp render, "
          f"{conv_s:.1f} s); mean radiance ours reference {ref.mean():.4f}, Mitsuba {conv.mean():.4f}")
    # The light is about 250 times brighter than the walls, so the few pixels on its edge
    # dominate the image mean: ours samples each pixel's centre, Mitsuba box-filters the
    # pixel. Away from it (2 pixels of margin) the two means compare the lighting itself.
    from scipy.ndimage import binary_dilation
    lum = np.array([0.2126, 0.7152, 0.0722])
    lo, lm = ref @ lum, conv @ lum
    near = binary_dilation((lo > 1.0) | (lm > 1.0), iterations=2)
    away = ~near
    print(f"  away from the light ({away.sum()} of {away.size} pixels): mean ours {lo[away].mean():.5f}, "
          f"Mitsuba {lm[away].mean():.5f}, ratio {lm[away].mean() / lo[away].mean():.4f}; "
          f"light coverage in pixels: ours {(lo > 1.0).sum()}, Mitsuba {lm[near].sum() / lo.max():.1f}")


if __name__ == "__main__":
    shadow_rays()
    table1()
    mitsuba_cornell()
