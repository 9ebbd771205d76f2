"""BoneSplit (paper 18) over a small CT archive on a Dask cluster: `wscg.distributed`.

Runs on a laptop as is (a LocalCluster of two single-threaded worker processes, three
generated fractured-shell phantoms, a few seconds):

    pip install 'wscg[dask]'
    python examples/dask_bone_separation.py [out_dir]

On several machines, start `dask-scheduler` on one and `dask-worker tcp://HOST:8786
--nworkers N --nthreads 1` on each, put the volumes where every worker can read them (a
shared filesystem, or s3://... URLs with s3fs installed) and pass
`--scheduler tcp://HOST:8786` instead of the LocalCluster (README, "Scale-out on Dask").
"""

import argparse
import pathlib
import tempfile

import numpy as np
from dask.distributed import Client, LocalCluster

import wscg
from wscg import distributed as wd


def make_archive(folder: pathlib.Path, n: int):
    """n CT phantoms as NIfTI files, with their seed volumes (.npy)."""
    paths, seeds = [], []
    for i in range(n):
        ct, seed, _ = wscg.volseg.make_fractured_shell_phantom((40, 40, 40), n_fragments=4,
                                                              seed=i)
        wscg.math.save_volume(folder / f"case{i:02d}.nii.gz", ct, spacing=(1.0, 0.8, 0.8))
        np.save(folder / f"case{i:02d}_seeds.npy", seed)
        paths.append(str(folder / f"case{i:02d}.nii.gz"))
        seeds.append(str(folder / f"case{i:02d}_seeds.npy"))
    return paths, seeds


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir", nargs="?", help="output folder (default: a temporary one)")
    ap.add_argument("--scheduler", help="address of a running dask-scheduler")
    ap.add_argument("--cases", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        out = pathlib.Path(args.out_dir) if args.out_dir else tmp / "out"
        paths, seeds = make_archive(tmp, args.cases)
        if args.scheduler:
            client = Client(args.scheduler)
        else:
            client = Client(LocalCluster(n_workers=2, threads_per_worker=1,
                                         dashboard_address=None))
        with client:
            print("dashboard:", client.dashboard_link)
            table = wd.split_bones(paths, seeds, out, client=client, progress=True)
        print()
        print(table[["case", "n_voxels", "n_bone_voxels", "n_labels", "n_iter", "seconds",
                     "n_meshes"]].to_string(index=False))
        print("written under", out)


if __name__ == "__main__":
    main()
