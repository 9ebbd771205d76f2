"""Paper 15 (convolution-based volume illumination): speed against VTK and the paper's
quality/speed study, on the frog tissue volume shipped inside the ``pyvista`` wheel.

Volume (spec section 3): ``pyvista/examples/frog_tissues.vti`` (500 x 470 x 136 labels,
spacing 1 x 1 x 1.5), read with ``wscg.volren.load_vti`` (pyvista itself is not imported),
labels mapped to densities and blurred by one voxel (``labels_to_density``), the steep
``skin_tf`` (an almost opaque body surface, like the paper's skin transfer function). Viewport 512 x 512, orthographic, orbit views, all threads.

1. Local illumination: our Blinn-Phong ray caster (sample distance 0.5 voxel, early ray
   termination) against VTK's ``vtkFixedPointVolumeRayCastMapper`` with ``ShadeOn`` on the
   same density volume (as uint8), same transfer function, sample distance 0.5, parallel
   projection, off screen (OSMesa). Spec target: ours <= 1.5x VTK's time. Both keep their
   prepared volume between frames (ours a ``PreparedVolume``, VTK its encoded volume and
   normals) and get a warm-up frame; the time of rendering from the float array (converted
   on every call) is printed too. Parts 2-4 render the ``PreparedVolume`` as well.
2. Table 1 / check 6: ICS at slice distance 0.2, 0.4, 0.6, 0.8 and SCS with 1..3
   sub-samples: time per frame and MAD against ICS(0.2); time(0.8)/time(0.2) (paper 0.32),
   cost of a sub-sample (paper 0.5 % on the GPU, spec limit 15 % on CPU), PI-ICS overhead.
3. Spec section 5 target: SCS(0.8, 3) >= 2.5x faster than ICS(0.2) with MAD <= 0.01.
4. Check 7: the section 2.7 protocol (alias-free = MAD <= 0.005 against ICS(0.2) and
   Laplacian error energy <= 2x that of ICS(0.1)) over slice distances 0.2..2.0 and 0..5
   sub-samples at 256 x 256 on 4 views: fastest alias-free SCS / PI-ICS / PI-SCS against the
   fastest alias-free ICS (paper 1.9x worst case, 2.37x on average; spec target >= 1.8x).

Environment: WSCG_VIEWS (views of parts 1-3, default 4).
"""

import importlib.util
import os
import sys
import time

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkOSOpenGLRenderWindow")

import numpy as np  # noqa: E402

from wscg import volren as V  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from _common import print_table, vtk_fixed_point_window  # noqa: E402

SIZE = 512
VIEWS = int(os.environ.get("WSCG_VIEWS", "4"))
SPACING = (1.5, 1.0, 1.0)  # (dz, dy, dx), wscg's order
SPACING_XYZ = SPACING[::-1]  # VTK's order


def frog():
    loc = importlib.util.find_spec("pyvista").submodule_search_locations[0]
    labels, spacing = V.load_vti(os.path.join(loc, "examples", "frog_tissues.vti"))
    assert tuple(spacing) == SPACING, spacing
    return V.labels_to_density(labels, spacing=SPACING, sigma=1.0)


def view_dirs(n, elevation=20.0):
    out = []
    for k in range(n):
        a = np.radians(30.0 + 360.0 * k / n)
        e = np.radians(elevation)
        out.append((-np.cos(e) * np.cos(a), -np.cos(e) * np.sin(a), -np.sin(e)))
    return out


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


def ours_frames(vol, tf, views, size, **kw):
    """Mean seconds per frame over ``views``; ``vol`` a PreparedVolume (or an array with
    ``spacing`` in ``kw``, which then pays the conversion every frame)."""
    imgs, total = [], 0.0
    for d in views:
        img, t = timed(lambda: V.render(vol, tf, view_dir=d, up=(0, 0, 1),
                                        size=(size, size), **kw))
        imgs.append(img)
        total += t
    return imgs, total / len(views)


def vtk_phong_time(vol, tf, views, size):
    """Mean seconds per frame of VTK's fixed-point ray caster with shading, same views."""
    vol8 = np.ascontiguousarray(np.round(vol * 255.0).astype(np.uint8))
    nz, ny, nx = vol8.shape
    n = len(tf)
    points = [(255.0 * i / (n - 1), r, g, b, a) for i, (r, g, b, a) in enumerate(tf)]
    win, ren = vtk_fixed_point_window(vol8, points, size, spacing=SPACING_XYZ,
                                      shade=(0.3, 0.6, 0.3, 20.0))
    sx, sy, sz = SPACING_XYZ
    centre = np.array([(nx - 1) * sx, (ny - 1) * sy, (nz - 1) * sz]) / 2
    radius = 0.5 * np.linalg.norm([nx * sx, ny * sy, nz * sz])
    total = 0.0
    for k, d in enumerate(views):
        c = ren.GetActiveCamera()
        c.ParallelProjectionOn()
        c.SetFocalPoint(*centre)
        c.SetPosition(*(centre - 3.0 * radius * np.array(d)))
        c.SetViewUp(0, 0, 1)
        c.SetParallelScale(radius)
        ren.ResetCameraClippingRange()
        if k == 0:
            win.Render()  # warm-up: VTK builds its encoded volume on the first frame
        _, t = timed(win.Render)
        total += t
    return total / len(views)


vol = frog()
tf = V.skin_tf()
# Normalised once with its empty-space cells and shading bricks, as VTK keeps its encoded
# volume and gradients between frames (both sides get a warm-up frame).
pv = V.PreparedVolume(vol, spacing=SPACING)
views = view_dirs(VIEWS)
print(f"frog density volume {vol.shape[::-1]} (x, y, z), spacing {SPACING_XYZ}, "
      f"{VIEWS} views, {SIZE} x {SIZE}")

# 1. Local illumination against VTK (same orthographic framing: VTK's parallel scale is the
# half-diagonal of the volume, so the pixel size is its diagonal over the image side).
nz, ny, nx = vol.shape
diag = float(np.linalg.norm([nx * SPACING_XYZ[0], ny * SPACING_XYZ[1], nz * SPACING_XYZ[2]]))
phong = dict(method="phong", slice_distance=0.5, pixel_size=diag / SIZE)
ours_frames(pv, tf, views[:1], SIZE, **phong)  # warm-up
_, t_phong = ours_frames(pv, tf, views, SIZE, **phong)
_, t_phong_array = ours_frames(vol, tf, views, SIZE, spacing=SPACING, **phong)
try:
    t_vtk = vtk_phong_time(vol, tf, views, SIZE)
except Exception as e:  # noqa: BLE001
    print(f"VTK unavailable: {e}")
    t_vtk = float("nan")
print_table("paper 15: Blinn-Phong ray casting, one 512 x 512 frame", [
    ("Phong ray caster, step 0.5", t_phong, "VTK fixed-point, ShadeOn", t_vtk),
])
print(f"(from a float32 array each frame, converting the volume every call: "
      f"{1e3 * t_phong_array:.1f} ms)")

# 2. Table 1 and the cost shape.
ref, t_ref = ours_frames(pv, tf, views, SIZE, method="ics", slice_distance=0.2)
print()
print(f"{'config':<22} {'ms/frame':>9} {'MAD':>8} {'time/ICS(0.2)':>14}")
times = {}
for ds in (0.2, 0.4, 0.6, 0.8):
    for m in range(0, 4):
        if ds == 0.2 and m == 0:
            imgs, t = ref, t_ref
        else:
            method = "ics" if m == 0 else "scs"
            imgs, t = ours_frames(pv, tf, views, SIZE, method=method, slice_distance=ds,
                                  n_subsamples=m)
        mad = np.mean([V.mean_abs_diff(a, b) for a, b in zip(imgs, ref)])
        times[(ds, m)] = (t, mad)
        print(f"{'ICS' if m == 0 else 'SCS'} ds={ds} m={m:<10} {1e3 * t:>9.1f} {mad:>8.4f} "
              f"{t / t_ref:>14.3f}")
pi_imgs, t_pi = ours_frames(pv, tf, views, SIZE, method="pi-ics", slice_distance=0.8)
pis_imgs, t_pis = ours_frames(pv, tf, views, SIZE, method="pi-scs", slice_distance=0.8,
                              n_subsamples=3)
mad_pis = np.mean([V.mean_abs_diff(a, b) for a, b in zip(pis_imgs, ref)])
t08 = times[(0.8, 0)][0]
print(f"time(0.8, m=0) / time(0.2, m=0) = {t08 / t_ref:.3f}   (paper 0.32, spec <= 0.35)")
per_sub = [(times[(0.8, m)][0] / t08 - 1.0) / m for m in (1, 2, 3)]
print("cost of one sub-sample at ds 0.8 (fraction of the m = 0 time): "
      + ", ".join(f"m={m}: {100 * p:.1f} %" for m, p in zip((1, 2, 3), per_sub))
      + "   (paper 0.5 % on a GPU, spec <= 15 %)")
print(f"PI-ICS(0.8) / ICS(0.8) time = {t_pi / t08:.3f}; PI-SCS(0.8, 3): "
      f"{1e3 * t_pis:.1f} ms, MAD {mad_pis:.4f}")

# 3. Spec section 5 target.
t_scs, mad_scs = times[(0.8, 3)]
print(f"SCS(0.8, 3) vs ICS(0.2): {t_ref / t_scs:.2f}x faster, MAD {mad_scs:.4f} "
      f"(target >= 2.5x with MAD <= 0.01)")

# 4. Check 7: the equal-quality protocol.
st = V.study(pv, tf, n_views=4, size=256)
alias_free = [e for e in st.entries if e.alias_free]
best_ics = min((e for e in alias_free if e.method == "ics"), key=lambda e: e.seconds,
               default=None)
best_other = min((e for e in alias_free if e.method != "ics"), key=lambda e: e.seconds,
                 default=None)
print()
print(f"study at 256 x 256, 4 views: reference ICS(0.2) {1e3 * st.reference_seconds:.1f} ms")
for e in st.entries:
    print(f"  {e.method:<7} ds={e.slice_distance:.1f} m={e.n_subsamples} "
          f"MAD={e.mad:.4f} energy={e.energy:.2e} {1e3 * e.seconds:7.1f} ms "
          f"{'alias-free' if e.alias_free else ''}")
if best_ics and best_other:
    print(f"fastest alias-free ICS: ds={best_ics.slice_distance:.1f} "
          f"{1e3 * best_ics.seconds:.1f} ms; fastest alias-free other: {best_other.method} "
          f"ds={best_other.slice_distance:.1f} m={best_other.n_subsamples} "
          f"{1e3 * best_other.seconds:.1f} ms; speed-up "
          f"{best_ics.seconds / best_other.seconds:.2f}x (spec >= 1.8x)")
