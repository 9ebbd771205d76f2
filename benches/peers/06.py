"""Paper 06 (localized-search HD video completion): wscg.video against per-frame PatchMatch
inpainting (``pypatchmatch``, the C++ PatchMatch of PyPatchMatch) and OpenCV's
``cv2.inpaint`` (Telea), on the specification's benchmark clip.

Workload (spec section 5): G2, a 1920 x 1080 x 30 pan of 8 px/frame under a static 240 x 160
logo hole (1.9 % of the pixels), with exact ground truth. Ours: ``complete_video`` with the
paper's defaults (stage 1 at 480 x 270, refinement, localized search at 960 x 540 and
1920 x 1080). Peers: ``patch_match.inpaint(frame, mask, patch_size=2)`` (5 x 5 patches) on each
of the 30 frames; ``cv2.inpaint(frame, mask, 3, cv2.INPAINT_TELEA)`` on each frame (a
diffusion: quality only). Targets: wall time <= 1.0x the per-frame PatchMatch total, SSIM in
the hole >= +0.05. Also our peak memory (VmHWM of a child process running only the
completion) against the bound 2 x input + 300 MB.

``WSCG_06_SCALE`` (default 1) divides the frame size for a quick run.
"""

import os
import subprocess
import sys
import time

import cv2
import numpy as np
from patchmatch import patch_match

from wscg import video as V

sys.path.insert(0, os.path.dirname(__file__))
from _common import print_table  # noqa: E402

SCALE = int(os.environ.get("WSCG_06_SCALE", "1"))
F, H, W = 30, 1080 // SCALE, 1920 // SCALE
HOLE = (160 // SCALE, 240 // SCALE)


def clip():
    return V.make_clip("pan", n_frames=F, height=H, width=W, step=8.0, hole=HOLE, seed=0)


clean, observed, mask = clip()
print(f"G2 pan {W} x {H} x {F}, hole {HOLE[1]} x {HOLE[0]} ({100 * mask.mean():.2f} % of the "
      f"pixels), input {observed.nbytes / 2**20:.0f} MB")

t = time.perf_counter()
ours, stats = V.complete_video(observed, mask, return_stats=True)
t_ours = time.perf_counter() - t

t = time.perf_counter()
pm = np.stack([patch_match.inpaint(f, m.astype(np.uint8) * 255, patch_size=2)
               for f, m in zip(observed, mask)])
t_pm = time.perf_counter() - t

t = time.perf_counter()
telea = np.stack([cv2.inpaint(f, m.astype(np.uint8), 3, cv2.INPAINT_TELEA)
                  for f, m in zip(observed, mask)])
t_telea = time.perf_counter() - t

print_table(f"paper 06: G2 pan {W}x{H}x{F}", [
    (f"complete_video {W}x{H}x{F}", t_ours, "pypatchmatch per frame", t_pm),
    (f"complete_video {W}x{H}x{F}", t_ours, "cv2.inpaint Telea per frame", t_telea),
])
print(f"our stages (s): low resolution {stats.seconds[0]:.1f}, refinement "
      f"{stats.seconds[1]:.1f}, localized search {stats.seconds[2]:.1f}")
print()
print("quality in the hole: SSIM / PSNR (dB) / flicker (the pan itself moves 8 px/frame)")
for name, v in [("wscg localized search", ours), ("pypatchmatch per frame", pm),
                ("cv2.inpaint Telea per frame", telea), ("ground truth", clean)]:
    print(f"{name:<30} {V.ssim_masked(v, clean, mask):.4f} / "
          f"{V.psnr_masked(v, clean, mask):6.2f} / {V.flicker(v, mask):.2f}")

child = f"""
import resource, os
from wscg import video as V
c, o, m = V.make_clip("pan", n_frames={F}, height={H}, width={W}, step=8.0, hole={HOLE}, seed=0)
del c
base = int([l for l in open("/proc/self/status") if l.startswith("VmHWM")][0].split()[1])
V.complete_video(o, m)
peak = int([l for l in open("/proc/self/status") if l.startswith("VmHWM")][0].split()[1])
print(base, peak)
"""
base, peak = map(int, subprocess.run([sys.executable, "-c", child], capture_output=True,
                                     text=True, check=True).stdout.split())
mb = observed.nbytes / 2**20
print(f"\npeak memory (VmHWM) of a process holding the clip and completing it: {peak / 1024:.0f} MB "
      f"(before the completion {base / 1024:.0f} MB); bound 2 x input + 300 MB = {2 * mb + 300:.0f} MB")
