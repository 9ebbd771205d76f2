"""Paper 18 (BoneSplit: random walks on the bone-only graph) against scikit-image's
``random_walker``, the library a user would pick (spec section 5).

Workload: the 256^3 fractured-shell phantom with K = 8 fragments (seed 0, about 0.97 M bone
voxels, the input of benches/volseg.rs). Both sides get the same weights: scikit-image uses
``w = exp(-beta_sk / (10 std(data)) (dg)^2) + 1e-10`` on ``data`` in [0, 1], so ``data`` is the
CT through our default window ``clip((ct + 1024) / 4095, 0, 1)``, ``beta_sk = 3000 * 10 *
data.std()``, and ours runs with ``eps = 1e-10, kappa = 0`` (seedless components dropped, as
scikit-image's ``-1`` labels). scikit-image's labels are ``-1`` outside the bone mask (it builds
the whole-grid edge list and removes those voxels), 0 on unseeded bone, 1..K on seeds.
Timed end to end (graph, solve, argmax), tol 3e-3:

- ours: ``wscg.volseg.random_walker_bone`` (K-block Jacobi-PCG, f32, all threads);
- ours with the paper's parameters (eps 0.01, kappa 1e-3), for reference;
- peer: ``skimage.segmentation.random_walker(mode="cg_j")`` and ``mode="cg_mg"`` (pyamg).

Each run happens in a fresh subprocess that loads the saved phantom, so that its peak resident
memory (``ru_maxrss``) above the loaded inputs can be reported; the labels are compared on the
bone voxels.

Environment: WSCG_REPEAT (timing repeats, default 1), WSCG_SIZE (cube side, default 256).
"""

import os
import resource
import subprocess
import sys
import time

import numpy as np

SIZE = int(os.environ.get("WSCG_SIZE", "256"))
REPEAT = int(os.environ.get("WSCG_REPEAT", "1"))
K = 8


def inputs():
    from wscg import volseg as V

    ct, truth, seeds = V.make_fractured_shell_phantom(shape=(SIZE, SIZE, SIZE), n_fragments=K, seed=0)
    return ct, truth, seeds


def run(which, out):
    """Runs one side in this process on the inputs saved beside ``out``; saves its labels to
    ``out`` and prints seconds, peak RSS and peak RSS above the loaded inputs (MB)."""
    folder = os.path.dirname(out)
    ct = np.load(os.path.join(folder, "ct.npy"))
    seeds = np.load(os.path.join(folder, "seeds.npy"))
    if which in ("cg_j", "cg_mg"):
        # scikit-image's input: the windowed CT in [0, 1] (in place, no temporaries).
        mask = ct >= 300
        data = ct.astype(np.float64)
        data += 1024.0
        data /= 4095.0
        np.clip(data, 0.0, 1.0, out=data)
    base_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    times = []
    for _ in range(REPEAT):
        t = time.perf_counter()
        if which in ("ours", "ours_paper"):
            from wscg import volseg as V

            kw = dict(eps=1e-10, kappa=0.0) if which == "ours" else {}
            labels = V.random_walker_bone(ct, seeds, tol=3e-3, **kw).astype(np.int32)
        else:
            from skimage.segmentation import random_walker

            markers = np.where(mask, seeds.astype(np.int32), -1)
            beta_sk = 3000.0 * 10.0 * data.std()
            mode = "cg_j" if which == "cg_j" else "cg_mg"
            labels = random_walker(data, markers, beta=beta_sk, mode=mode, tol=3e-3)
        times.append(time.perf_counter() - t)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    np.save(out, labels)
    print(f"{min(times):.4f} {peak / 1024:.1f} {(peak - base_rss) / 1024:.1f}")


def child(which, out):
    r = subprocess.run([sys.executable, __file__, which, out], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr, file=sys.stderr)
        return None
    secs, peak, above = (float(v) for v in r.stdout.split()[-3:])
    return secs, peak, above, np.load(out)


def prepare(folder):
    """Writes the phantom's CT, seeds and truth to ``folder`` (run in a child: the parent stays
    small, since Linux carries ``ru_maxrss`` over ``fork`` and ``exec`` into the children)."""
    ct, truth, seeds = inputs()
    for name, a in (("ct", ct), ("seeds", seeds), ("truth", truth)):
        np.save(os.path.join(folder, name + ".npy"), a)


def main():
    import tempfile

    results = {}
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([sys.executable, __file__, "prepare", d], check=True)
        for which in ("ours", "ours_paper", "cg_j", "cg_mg"):
            results[which] = child(which, os.path.join(d, which + ".npy"))
        truth = np.load(os.path.join(d, "truth.npy"))
    bone = truth > 0
    from wscg import volseg as V

    print(f"paper 18: {SIZE}^3 phantom, K = {K}, {int(bone.sum())} bone voxels, tol 3e-3, "
          f"repeat {REPEAT}")
    print(f"{'run':<44} {'seconds':>9} {'peak RSS MB':>12} {'above inputs':>13} {'DSC':>7}")
    names = {
        "ours": "wscg random_walker_bone (eps 1e-10, kappa 0)",
        "ours_paper": "wscg random_walker_bone (paper eps, kappa)",
        "cg_j": "skimage random_walker cg_j",
        "cg_mg": "skimage random_walker cg_mg (pyamg)",
    }
    for which, r in results.items():
        if r is None:
            print(f"{names[which]:<44} failed")
            continue
        secs, peak, above, labels = r
        lab = np.where(bone, np.maximum(labels, 0), 0).astype(np.uint16)
        dsc = V.dice(lab, truth)
        print(f"{names[which]:<44} {secs:>9.3f} {peak:>12.1f} {above:>13.1f} {dsc:>7.4f}")
    ours, peer = results["ours"], results["cg_j"]
    if ours and peer:
        agree = float(np.mean(ours[3][bone] == peer[3][bone]))
        print(f"labels agree with cg_j on {100 * agree:.3f} % of bone voxels")
        print(f"cg_j / ours: time {peer[0] / ours[0]:.2f}x, peak RSS above inputs "
              f"{peer[2] / max(ours[2], 1.0):.2f}x")
    if ours and results["cg_mg"]:
        print(f"cg_mg / ours: time {results['cg_mg'][0] / ours[0]:.2f}x")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "prepare":
        prepare(sys.argv[2])
    elif len(sys.argv) == 3:
        run(sys.argv[1], sys.argv[2])
    else:
        main()
