#!/usr/bin/env python3
"""Throughput of the wscg.distributed pipelines on LocalClusters of 1 and 2 worker processes
x threads per worker, against the single-process loop over the same batch (BENCHMARKS.md,
"Scale-out on Dask"), and the peak memory of one task of each pipeline.

    python benches/dask_scaling.py [--repeat 3] [--pipelines bones,identify,video,mri] [--scale 1]

Needs `pip install 'wscg[dask]'`. Each configuration runs the batch `--repeat` times on a
warm cluster (workers started, wscg imported, the gallery model scattered) and keeps the
fastest run; the load average (`uptime`) is printed with each line. `--scale K` makes every
batch K times as many cases (the same case sizes), so that the per-batch cost of the cluster
(submission, scatter, gathering the results) weighs less against the work.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

import wscg
from wscg import distributed as wd


def _bones(tmp: pathlib.Path, n: int = 8, size: int = 96):
    paths, seeds = [], []
    for i in range(n):
        ct, seed, _ = wscg.volseg.make_fractured_shell_phantom((size,) * 3, n_fragments=5,
                                                              seed=i)
        wscg.math.save_volume(tmp / f"ct{i}.nii.gz", ct)
        np.save(tmp / f"ct{i}_seeds.npy", seed)
        paths.append(str(tmp / f"ct{i}.nii.gz"))
        seeds.append(str(tmp / f"ct{i}_seeds.npy"))
    return paths, seeds


def _ears(n_subjects: int = 200, n_probes: int = 2):
    data = wscg.ear.make_ears(n_subjects=n_subjects, n_probes=n_probes, seed=0)
    return list(data.probes), wscg.ear.EarMatcher().fit(wscg.ear.enroll_many(data.enrol))


def _clips(n: int = 4):
    clips, masks = [], []
    for i in range(n):
        _, observed, mask = wscg.video.make_clip("sprite", n_frames=10, height=90, width=120,
                                                 radius=10.0, seed=i)
        clips.append(observed)
        masks.append(mask)
    return clips, masks


def _mri(n_slices: int = 8, n: int = 96):
    image = wscg.csmri.make_shepp_logan_image(n)
    mask, _ = wscg.csmri.mask_pseudo_radial((n, n), rate=0.3)
    stack = np.stack([np.roll(image, 3 * i, axis=1) for i in range(n_slices)])
    return [np.stack([wscg.csmri.simulate(s, mask) for s in stack])], [mask]


def _batches(tmp: pathlib.Path, scale: int = 1):
    """name -> (call(client) running the whole batch, number of cases); `scale` multiplies
    the number of cases of every batch."""
    paths, seeds = _bones(tmp, n=8 * scale)
    probes, gallery = _ears(n_probes=2 * scale)
    clips, masks = _clips(4 * scale)
    kspaces, kmasks = _mri(8 * scale)
    counter = iter(range(10**6))

    def out():  # a fresh folder per run: nothing skipped
        return tmp / f"out{next(counter)}"

    return {
        "bones": (lambda c: wd.split_bones(paths, seeds, out(), client=c, meshes=True),
                  len(paths), "volumes"),
        "identify": (lambda c: wd.identify(probes, gallery, client=c), len(probes), "probes"),
        "video": (lambda c: wd.complete_videos(clips, masks, out(), client=c,
                                               params={"lowres_width": 120}),
                  len(clips), "clips"),
        "mri": (lambda c: wd.reconstruct_mri(kspaces, kmasks, out(), client=c,
                                             priors=["udct"], params={"max_iter": 40}),
                kspaces[0].shape[0], "slices"),
    }


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _best(call, client, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call(client)
        times.append(time.perf_counter() - t0)
    return min(times)


def _memory(name: str, tmp: pathlib.Path) -> None:
    """Peak resident memory of one task of `name` in a fresh process, above its memory
    after `import wscg, dask` (printed as MiB); the inputs are files written here."""
    import pickle

    if name == "bones":
        run = (f"wd.split_bones([{str(tmp / 'ct0.nii.gz')!r}], [{str(tmp / 'ct0_seeds.npy')!r}], "
               f"{str(tmp / 'mem')!r})")
    elif name == "identify":
        probes, gallery = _ears(n_subjects=200, n_probes=1)
        (tmp / "gallery.pkl").write_bytes(pickle.dumps(gallery))
        np.save(tmp / "probe.npy", probes[0])
        run = (f"wd.identify([{str(tmp / 'probe.npy')!r}], "
               f"pickle.loads(open({str(tmp / 'gallery.pkl')!r}, 'rb').read()))")
    elif name == "video":
        clips, masks = _clips(1)
        np.save(tmp / "clip.npy", clips[0])
        np.save(tmp / "clip_mask.npy", masks[0])
        run = (f"wd.complete_videos([{str(tmp / 'clip.npy')!r}], "
               f"[{str(tmp / 'clip_mask.npy')!r}], {str(tmp / 'mem')!r}, "
               "params={'lowres_width': 120})")
    else:
        k, m = _mri(1)
        np.save(tmp / "k.npy", k[0])
        run = (f"wd.reconstruct_mri([{str(tmp / 'k.npy')!r}], [np.asarray({m[0].tolist()!r})], "
               "priors=['udct'], params={'max_iter': 40})")
    code = ("import os, pickle, resource, dask, pandas, numpy as np, wscg\n"
            "import wscg.distributed as wd\n"
            "base = int(open('/proc/self/statm').read().split()[1]) * os.sysconf('SC_PAGE_SIZE')\n"
            "with dask.config.set(scheduler='synchronous'):\n"
            f"    {run}\n"
            "peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024\n"
            "print(peak / 2**20, base / 2**20)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=dict(os.environ, WSCG_NUM_THREADS="1"))
    if r.returncode:
        print(f"{name}: memory run failed: {r.stderr[-2000:]}")
        return
    peak, base = map(float, r.stdout.split()[-2:])
    print(f"memory {name}: peak RSS {peak:.0f} MiB, {peak - base:.0f} MiB above the process "
          f"after import ({base:.0f} MiB)", flush=True)


def _sizes(tmp: pathlib.Path) -> None:
    """What one task moves: its input as stored or pickled, and the gallery model."""
    import pickle

    ct = tmp / "ct0.nii.gz"
    probes, gallery = _ears()
    clips, _ = _clips(1)
    kspaces, _ = _mri(1)
    print(f"sizes: CT volume file {ct.stat().st_size / 2**20:.2f} MiB, ear probe "
          f"{len(pickle.dumps(probes[0])) / 2**10:.0f} KiB, ear gallery model "
          f"{len(pickle.dumps(gallery)) / 2**10:.0f} KiB, clip "
          f"{len(pickle.dumps(clips[0])) / 2**10:.0f} KiB, k-space slice "
          f"{len(pickle.dumps(kspaces[0][0])) / 2**10:.0f} KiB", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--pipelines", default="bones,identify,video,mri")
    ap.add_argument("--scale", type=int, default=1,
                    help="cases per batch, as a multiple of the default batches")
    ap.add_argument("--no-memory", action="store_true")
    ap.add_argument("--memory-only", action="store_true")
    args = ap.parse_args()
    import dask
    from dask.distributed import Client, LocalCluster

    names = args.pipelines.split(",")
    if args.memory_only:
        with tempfile.TemporaryDirectory() as tmp:
            _bones(pathlib.Path(tmp), n=1)
            for name in names:
                _memory(name, pathlib.Path(tmp))
        return
    with tempfile.TemporaryDirectory() as tmp:
        batches = _batches(pathlib.Path(tmp), args.scale)
        _sizes(pathlib.Path(tmp))
        # The single-process loop: Dask's synchronous scheduler in this process, wscg's
        # pool at one thread, then at every core.
        for n_threads in (1, os.cpu_count() or 1):
            wscg.set_num_threads(n_threads)
            with dask.config.set(scheduler="synchronous"):
                for name in names:
                    call, n, what = batches[name]
                    t = _best(call, None, args.repeat)
                    print(f"single process, {n_threads} wscg threads: {name}: {t:.2f} s, "
                          f"{n / t:.2f} {what}/s (load {_load()})", flush=True)
        wscg.set_num_threads(None)
        for workers, threads in ((1, 1), (1, 2), (2, 1)):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=threads,
                                   processes=True, dashboard_address=None, silence_logs=40)
            with Client(cluster) as client:
                for name in names:
                    call, n, what = batches[name]
                    call(client)  # warm: imports, scattered model
                    t = _best(call, client, args.repeat)
                    print(f"{workers}x{threads}: {name}: {t:.2f} s, {n / t:.2f} {what}/s "
                          f"(load {_load()})", flush=True)
            cluster.close()
        if not args.no_memory:
            for name in names:
                _memory(name, pathlib.Path(tmp))


if __name__ == "__main__":
    main()
