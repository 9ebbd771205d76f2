"""Ear identification (paper 14) of many probes against a gallery on a Dask cluster: the
fitted EarMatcher is sent to every worker once, the probes are split into partitions
(`wscg.distributed.identify`). The same call takes a fitted `wscg.gait.GaitRecognizer`
(paper 17) or a `wscg.biometrics.FDKECA` model (paper 01).

    pip install 'wscg[dask]'
    python examples/dask_identification.py [--scheduler tcp://HOST:8786]
"""

import argparse

from dask.distributed import Client, LocalCluster

import wscg
from wscg import distributed as wd


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scheduler", help="address of a running dask-scheduler")
    ap.add_argument("--subjects", type=int, default=30)
    ap.add_argument("--probes", type=int, default=2, help="probes per subject")
    args = ap.parse_args()
    data = wscg.ear.make_ears(n_subjects=args.subjects, n_probes=args.probes, seed=0)
    gallery = wscg.ear.EarMatcher().fit(wscg.ear.enroll_many(data.enrol))
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        client = Client(LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None))
    with client:
        table = wd.identify(list(data.probes), gallery, client=client, top_k=5,
                            labels=list(range(args.subjects)), progress=True)
    print()
    top1 = table[table["rank"] == 1].set_index("probe")["identity"]
    truth = data.labels[top1.index.to_numpy()]
    print(f"{len(data.probes)} probes, {int(table.rejected.sum())} rejected as occluded; "
          f"rank-1 rate of the ranked probes: {(top1.to_numpy() == truth).mean():.2f}")
    print(table.head(10).to_string(index=False))


if __name__ == "__main__":
    main()
