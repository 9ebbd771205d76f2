"""Video completion (paper 06) of a few clips and compressed-sensing MRI (paper 11) of every
slice of a small scan with two priors on a Dask cluster, one task per clip or slice
(`wscg.distributed.complete_videos`, `wscg.distributed.reconstruct_mri`).

    pip install 'wscg[dask]'
    python examples/dask_video_mri.py [out_dir] [--scheduler tcp://HOST:8786]
"""

import argparse
import pathlib
import tempfile

import numpy as np
from dask.distributed import Client, LocalCluster

import wscg
from wscg import distributed as wd


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir", nargs="?", help="output folder (default: a temporary one)")
    ap.add_argument("--scheduler", help="address of a running dask-scheduler")
    args = ap.parse_args()
    clips, masks = [], []
    for i, kind in enumerate(("sprite", "pan", "zoom")):
        _, observed, mask = wscg.video.make_clip(kind, n_frames=8, height=60, width=80,
                                                 radius=8.0, hole=(12, 14), seed=i)
        clips.append(observed)
        masks.append(mask)
    n = 64
    image = wscg.csmri.make_shepp_logan_image(n)
    mask, _ = wscg.csmri.mask_pseudo_radial((n, n), rate=0.3)
    scan = np.stack([wscg.csmri.simulate(s, mask) for s in (image, image[::-1], image.T)])
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(args.out_dir) if args.out_dir else pathlib.Path(tmp)
        if args.scheduler:
            client = Client(args.scheduler)
        else:
            client = Client(LocalCluster(n_workers=2, threads_per_worker=1,
                                         dashboard_address=None))
        with client:
            videos = wd.complete_videos(clips, masks, out / "videos", client=client,
                                        params={"lowres_width": 80})
            mri = wd.reconstruct_mri([scan], [mask], out / "mri", client=client,
                                     priors=["udct", "db4"], params={"max_iter": 30})
        print(videos[["clip", "n_frames", "n_hole_pixels", "energy", "seconds"]]
              .to_string(index=False))
        print(mri[["kspace", "slice", "prior", "n_iter", "seconds"]].to_string(index=False))
        print("written under", out)


if __name__ == "__main__":
    main()
