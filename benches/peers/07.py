"""Paper 07 peer benchmark: our spectral paint renderer against Mitsuba 3 on the same plate.

The plate (aluminium flakes of radius 30 µm, density 6.5, in a 20.24 µm binder under a 40 µm
coat of index 1.5) is exported with ``wscg.raytrace.plate_layout`` and rebuilt in Mitsuba:
one ``shapegroup`` of ``disk`` shapes per tile of the pool, one ``instance`` per cell with
the cell's translation and quarter turns, a ``conductor`` BSDF with aluminium's n and k
divided by the binder's index, the coat as a ``dielectric`` interface, and the lamp as a
distant sphere emitter of the same angular radius (1 degree, 75 degrees above the plate),
CIE daylight at 4700 K. View: the cyclopean eye 77 cm above the plate, 20 x 20 mm on
256 x 256 pixels, 64 samples per pixel, ``path`` integrator.

Mitsuba does not clip a flake to its cell, so the two scenes differ at cell edges; the two
images correlate (printed), and the timing compares the same work. Both sample each pixel on a
jittered 8 x 8 grid. ``llvm_ad_spectral`` is tried only with ``WSCG_07_LLVM=1``: on the
2-core, 24 GiB machine of BENCHMARKS.md it was killed for memory at 4 spp on this scene of
2025 instances. Noise is compared through the relative RMSE between two renders
with different seeds (divided by sqrt 2), and the ratio of ``time x variance`` gives the
speed at equal error.
"""

import os

import numpy as np

from _common import best_time, print_table
from wscg import raytrace as rt

REGION = 20.0
PIX = 256
SPP = 64
TOP_MM = (20.24 + 40.0) * 1e-3
PARAMS = dict(seed=3)


def ours(seed):
    mag = PIX * 0.53136 / 1920 * 1e3 / REGION
    xyz = rt.render_plate("cyclopean", region_mm=(-REGION / 2, -REGION / 2, REGION / 2, REGION / 2),
                          magnification=mag, spp=SPP, render_seed=seed, light_elevation_deg=75.0,
                          light_deg=1.0, **PARAMS)
    return xyz[..., 1]


def rotation_to(n):
    """3 x 3 rotation taking +z to the unit vector n."""
    z = np.array([0.0, 0.0, 1.0])
    v = np.cross(z, n)
    c = float(n @ z)
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def mitsuba_scene(mi):
    tiles, cells = rt.plate_layout((-REGION / 2, -REGION / 2, REGION / 2, REGION / 2), **PARAMS)
    lam = np.arange(380.0, 781.0, 5.0)
    nk = rt.aluminium_nk(lam)
    eta = [(float(w), float(v / 1.5)) for w, v in zip(lam, nk[:, 0])]
    k = [(float(w), 6.0 / 1.5) for w in lam]
    d47 = [(float(w), float(v)) for w, v in zip(lam, rt.daylight(4700.0))]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 10},
        "flake": {"type": "conductor", "eta": {"type": "spectrum", "value": eta},
                  "k": {"type": "spectrum", "value": k}},
        "sensor": {
            "type": "perspective", "fov_axis": "x",
            "fov": float(2 * np.degrees(np.arctan(REGION / 2 / 770.0))),
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 770.0 + TOP_MM],
                                                       target=[0, 0, TOP_MM], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": PIX, "height": PIX, "rfilter": {"type": "box"}},
            "sampler": {"type": "stratified", "sample_count": SPP},
        },
        "coat": {"type": "rectangle", "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
                 "to_world": mi.ScalarTransform4f().translate([0, 0, TOP_MM]).scale([60.0, 60.0, 1.0])},
    }
    elev = np.radians(75.0)
    d = np.array([0.0, np.cos(elev), np.sin(elev)])
    dist = 1e5
    scene["lamp"] = {"type": "sphere", "center": (d * dist).tolist(),
                     "radius": float(dist * np.sin(np.radians(1.0))),
                     "emitter": {"type": "area", "radiance": {"type": "spectrum", "value": d47}}}
    for t, flakes in enumerate(tiles):
        group = {"type": "shapegroup"}
        for i, f in enumerate(flakes):
            m = np.eye(4)
            m[:3, :3] = rotation_to(np.array([f["nx"], f["ny"], f["nz"]])) * (f["r"] * 1e-3)
            m[:3, 3] = [f["cx"] * 1e-3, f["cy"] * 1e-3, f["cz"] * 1e-3]
            group[f"d{i}"] = {"type": "disk", "to_world": mi.ScalarTransform4f(m.tolist()),
                              "bsdf": {"type": "ref", "id": "flake"}}
        scene[f"tile{t}"] = group
    half = 0.45 / 2
    for c, (x0, y0, t, q) in enumerate(cells):
        m = np.eye(4)
        ang = q * np.pi / 2
        m[:2, :2] = [[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]]
        # p = corner + L/2 + R (q - L/2), in mm.
        shift = np.array([x0 * 1e-3 + half, y0 * 1e-3 + half]) - m[:2, :2] @ [half, half]
        m[:2, 3] = shift
        scene[f"cell{c}"] = {"type": "instance", "to_world": mi.ScalarTransform4f(m.tolist()),
                             "shapegroup": {"type": "ref", "id": f"tile{t}"}}
    return scene


def rel_noise(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2) / 2) / max(np.mean(a), 1e-30))


def main():
    rows = []
    t_ours = best_time(lambda: ours(1), repeat=3)
    n_ours = rel_noise(ours(1), ours(2))
    lit = float(np.mean(ours(1) > 0))
    print(f"ours: {t_ours:.3f} s, relative noise {n_ours:.4f}, lit pixels {lit:.3f}")
    try:
        import mitsuba as mi
    except ImportError:
        print("mitsuba is not installed (pip install mitsuba): peer skipped")
        return
    variants = ["scalar_spectral"] + (["llvm_ad_spectral"] if os.environ.get("WSCG_07_LLVM") else [])
    for variant in variants:
        try:
            mi.set_variant(variant)
        except Exception as e:  # the LLVM variant needs libLLVM
            print(f"{variant}: unavailable ({e})")
            continue
        scene = mi.load_dict(mitsuba_scene(mi))

        def render(seed):
            img = np.array(mi.render(scene, seed=seed, spp=SPP))
            return img[..., :3] @ np.array([0.2126, 0.7152, 0.0722])

        t_peer = best_time(lambda: render(1), repeat=1 if variant.startswith("scalar") else 3)
        n_peer = rel_noise(render(1), render(2))
        img = render(1)
        corr = float(np.corrcoef(img.ravel(), ours(1).ravel())[0, 1])
        print(f"mitsuba {variant}: {t_peer:.3f} s, relative noise {n_peer:.4f}, "
              f"lit pixels {float(np.mean(img > 0)):.3f}, correlation with ours {corr:.3f}")
        rows.append(("render 20x20 mm 256x256, 64 spp", t_ours, f"mitsuba {variant}", t_peer))
        rows.append(("  same, at equal relative RMSE", t_ours * n_ours ** 2,
                     f"mitsuba {variant}", t_peer * n_peer ** 2))
    print_table("paper 07: metallic-flake plate, cyclopean eye", rows)


if __name__ == "__main__":
    main()
