"""Paper 03 (hybrid ROI visualisation): the server's block Haar codec against PyWavelets.

Workload (spec section 5): the 4-step 3-D Haar transform of every 16^3 block of a volume,
``pywt.wavedecn(blocks, 'haar', mode='periodization', level=4, axes=(1, 2, 3))`` on the
``(n_blocks, 16, 16, 16)`` float32 array against ``wscg.volren.haar_blocks`` on the same
array (transform only, no quantisation or coding; both produce every coefficient). Volumes:
the head phantom at the paper's skull size (256 x 256 x 112, 1792 blocks) and the thorax
phantom at 256^3 (4096 blocks). pytest checks that the coefficients agree up to the
per-level scale (test_block_haar_matches_pywavelets).

Rendering (spec section 5): a 512 x 512 frame of the thorax phantom (256^3 here; set
WSCG_THORAX=512 for the paper's size), median of 10 frames after a warm-up, all threads:
our hybrid client (the 1/64 context everywhere, the Gradient Octree in a 128 x 80 x 128 bone
ROI at 256^3) and our full-resolution reference ray caster, against VTK's
``vtkFixedPointVolumeRayCastMapper`` on the full-resolution volume with the canonical
transfer function, the same camera, sample distance 0.5 voxel, no automatic sample-distance
reduction, off screen (OSMesa).
"""

import os
import sys

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkOSOpenGLRenderWindow")

import numpy as np  # noqa: E402
import pywt  # noqa: E402

from wscg import volren as V  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table, vtk_fixed_point_window  # noqa: E402


def blocks_of(vol):
    z, y, x = (s // 16 * 16 for s in vol.shape)
    v = vol[:z, :y, :x].astype(np.float32)
    b = v.reshape(z // 16, 16, y // 16, 16, x // 16, 16).transpose(0, 2, 4, 1, 3, 5)
    return np.ascontiguousarray(b.reshape(-1, 16, 16, 16))


rows = []
for name, shape in [("head", (112, 256, 256)), ("thorax", (256, 256, 256))]:
    blocks = blocks_of(V.make_phantom(name, shape, seed=1))
    ours = best_time(lambda: V.haar_blocks(blocks), repeat=5)
    peer = best_time(lambda: pywt.wavedecn(blocks, "haar", mode="periodization", level=4,
                                           axes=(1, 2, 3)), repeat=3)
    rows.append((f"{name} {len(blocks)} blocks 16^3, 4 steps", ours, "pywt.wavedecn haar", peer))
print_table("paper 03: block Haar transform, wscg.volren vs PyWavelets", rows)


def vtk_frame_time(vol, tf, cam, size, frames=10):
    """Median seconds of a VTK fixed-point ray-cast frame."""
    import time

    win, ren = vtk_fixed_point_window(vol, tf, size)
    c = ren.GetActiveCamera()
    c.SetPosition(*cam["eye"])
    c.SetFocalPoint(*cam["target"])
    c.SetViewUp(*cam["up"])
    c.SetViewAngle(cam["fov_deg"])
    ren.ResetCameraClippingRange()
    win.Render()
    times = []
    for _ in range(frames):
        t = time.perf_counter()
        win.Render()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


n = int(os.environ.get("WSCG_THORAX", "256"))
vol = V.make_phantom("thorax", (n, n, n), seed=1)
tfs = V.phantom_tfs("thorax")
server = V.HybridServer(vol, tfs)
client = V.HybridClient(server.static_package())
q = lambda f: int(f * n)  # noqa: E731
client.set_roi(server.roi_package((q(0.25), q(0.75), q(0.19), q(0.5), q(0.25), q(0.75))))
cam = V.orbit_camera(vol.shape)
size = 512
t_vtk = vtk_frame_time(vol, tfs[0], cam, size)
t_hybrid = best_time(lambda: client.render(**cam, size=(size, size)), repeat=10)
t_ref = best_time(lambda: V.render_reference(vol, tfs[0], **cam, size=(size, size)), repeat=3)
print()
print_table(f"paper 03: one 512 x 512 frame of the {n}^3 thorax", [
    ("hybrid client (context + ROI octree)", t_hybrid, "VTK fixed-point full res", t_vtk),
    ("our full-resolution reference", t_ref, "VTK fixed-point full res", t_vtk),
])
