"""Paper 11 peers: the UDCT against the `curvelets` (1.2) and `ucurv` (0.1.1) packages, the
wrapping FDCT against `curvepy-fdct` (1.2.0, numpy + Cython; reconstruction error reported), and
C-SALSA against sigpy's L1WaveletRecon and BART's `pics -l1` on the same 256^2 problem
(analytic Shepp-Logan k-space, 40% Cartesian, 70 iterations). Prints ours, peer, ratio and
the PSNR beside every solver time.

    python benches/peers/11.py          # needs wscg (release build), curvelets, ucurv, sigpy;
                                        # curvepy-fdct and BART are used when present
"""

import os
import shutil
import subprocess
import tempfile
import time

import numpy as np

from wscg import csmri


def best(f, repeat=5):
    t = []
    for _ in range(repeat):
        s = time.perf_counter()
        out = f()
        t.append(time.perf_counter() - s)
    return min(t), out


def row(name, ours, peer, extra=""):
    print(f"{name:48s} ours {ours * 1e3:9.2f} ms   peer {peer * 1e3:9.2f} ms   "
          f"peer/ours {peer / ours:6.2f}x  {extra}")


def transforms():
    from curvelets.numpy import UDCT
    import ucurv
    for n in [256, 512]:
        x = csmri.make_shepp_logan_image(n)
        ours = csmri.Udct((n, n), wedges=[[6, 6]])
        t_ours, _ = best(lambda: ours.backward(*ours.forward(x)))
        cv = UDCT((n, n), angular_wedges_config=np.array([[6, 6]]), window_overlap=0.1)
        t_cv, y = best(lambda: cv.backward(cv.forward(x)), repeat=3)
        row(f"udct [[6,6]] forward+backward {n}^2 (curvelets)", t_ours, t_cv,
            f"curvelets rel. error {np.linalg.norm(y - x) / np.linalg.norm(x):.1e}")
        uc = ucurv.udct((n, n), [[6, 6]])
        t_uc, _ = best(lambda: ucurv.ucurvinv(ucurv.ucurvfwd(x, uc), uc), repeat=3)
        row(f"udct [[6,6]] forward+backward {n}^2 (ucurv)", t_ours, t_uc)


def fdct_transforms():
    try:
        from curvepy.curvepy import CurveletFrequencyGrid
    except ImportError:
        print("curvepy-fdct not installed; FDCT peer skipped")
        return
    for n in [256, 512]:
        x = csmri.make_shepp_logan_image(n)
        ours = csmri.Fdct((n, n))
        t_ours, y = best(lambda: ours.backward(ours.forward(x)))
        # The same number of scales as ours (ceil(log2 n) - 3, CurveLab's default).
        cp = CurveletFrequencyGrid(n, n, ours.n_scales)
        cp.forward_transform(x)  # fills its window cache, as a user's second call would
        t_cp, z = best(lambda: cp.inverse_transform(cp.forward_transform(x)), repeat=3)
        err = lambda v: np.linalg.norm(np.real(v) - x) / np.linalg.norm(x)
        row(f"fdct forward+backward {n}^2 (curvepy-fdct)", t_ours, t_cp,
            f"rel. error ours {err(y):.1e}, curvepy {err(z):.1e}; "
            f"coefficients per pixel ours {ours.redundancy:.2f}, curvepy "
            f"{sum(c.size for s in cp.forward_transform(x) for c in s) / n / n:.2f}")
    n = 256
    k = csmri.make_shepp_logan_kspace(n)
    ref = csmri.make_shepp_logan_reference(n)
    m = csmri.mask_cartesian((n, n), 0.4, seed=1)
    t_f, xf = best(lambda: csmri.reconstruct(k, m, prior="fdct"), repeat=3)
    print(f"{'csalsa fdct-l1 70 it 256^2':48s} ours {t_f * 1e3:9.2f} ms   PSNR {csmri.psnr(ref, xf):.2f} dB")


def fitted_psnr(ref, x):
    """PSNR after the best real scale (peers normalise differently) and either centring."""
    out = []
    for y in (x, np.fft.fftshift(x), np.fft.ifftshift(x)):
        a = np.abs(y)
        s = np.vdot(a, np.abs(ref)).real / max(np.vdot(a, a).real, 1e-300)
        out.append(csmri.psnr(ref, s * y))
    return max(out)


def solvers():
    n = 256
    k = csmri.make_shepp_logan_kspace(n)
    ref = csmri.make_shepp_logan_reference(n)
    m = csmri.mask_cartesian((n, n), 0.4, seed=1)
    y = np.where(m, k, 0)
    t_u, xu = best(lambda: csmri.reconstruct(y, m), repeat=3)
    print(f"{'csalsa udct-l1 70 it 256^2':48s} ours {t_u * 1e3:9.2f} ms   PSNR {csmri.psnr(ref, xu):.2f} dB")
    t_w, xw = best(lambda: csmri.reconstruct(y, m, prior="db4"), repeat=3)
    p_w = csmri.psnr(ref, xw)
    try:
        import sigpy.mri.app as app
        lam = 0.001 * np.abs(np.fft.ifft2(y, norm="ortho")).max()

        def run_sigpy():
            return app.L1WaveletRecon(np.fft.fftshift(y)[None], np.ones((1, n, n), complex), lam,
                                      weights=np.fft.fftshift(m).astype(float), max_iter=70,
                                      show_pbar=False).run()
        t_s, xs = best(run_sigpy, repeat=3)
        row("csalsa db4-l1 70 it 256^2 (sigpy L1WaveletRecon)", t_w, t_s,
            f"PSNR ours {p_w:.2f} dB, sigpy {fitted_psnr(ref, np.asarray(xs)):.2f} dB")
    except ImportError:
        print("sigpy not installed")
    if shutil.which("bart"):
        with tempfile.TemporaryDirectory() as d:
            def wcfl(name, a):
                a = np.asarray(a, np.complex64)
                dims = list(a.shape) + [1] * (16 - a.ndim)
                with open(os.path.join(d, name + ".hdr"), "w") as f:
                    f.write("# Dimensions\n" + " ".join(map(str, dims)) + "\n")
                a.T.tofile(os.path.join(d, name + ".cfl"))

            def rcfl(name):
                dims = [int(v) for v in open(os.path.join(d, name + ".hdr")).read().split("\n")[1].split()]
                a = np.fromfile(os.path.join(d, name + ".cfl"), np.complex64)
                return a.reshape(dims[::-1]).T.reshape(dims[:2])

            wcfl("ksp", np.fft.fftshift(y)[:, :, None, None])
            wcfl("sens", np.ones((n, n, 1, 1)))

            def run_bart():
                subprocess.run(["bart", "pics", "-S", "-l1", "-r", "0.001", "-i", "70",
                                os.path.join(d, "ksp"), os.path.join(d, "sens"),
                                os.path.join(d, "out")], check=True, capture_output=True)
                return rcfl("out")
            t_b, xb = best(run_bart, repeat=3)
            row("csalsa db4-l1 70 it 256^2 (bart pics -l1)", t_w, t_b,
                f"PSNR ours {p_w:.2f} dB, bart {fitted_psnr(ref, xb):.2f} dB")
    else:
        print("bart not found; skipped")


if __name__ == "__main__":
    transforms()
    fdct_transforms()
    solvers()
