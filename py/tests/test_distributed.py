"""wscg.distributed on a LocalCluster of two worker processes on localhost: every pipeline
equals the sequential loop over the same cases exactly, a worker killed during a run loses no
finished case and the run completes, a model pickled in this process predicts identically in
a worker, and the workers' wscg thread pools follow their Dask threads."""

from __future__ import annotations

import json
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import wscg
from wscg import distributed as wd

dask = pytest.importorskip("dask", reason="dask is a test requirement (py/requirements-test.txt)")
distributed = pytest.importorskip("distributed")
pd = pytest.importorskip("pandas")

SHAPE = (28, 28, 28)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None,
                                       silence_logs=40)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def _no_default_client(c):
    """The pipelines with client=None use the current Client; the sequential references
    must run in this process (Dask's synchronous scheduler, no client)."""
    return dask.config.set(scheduler="synchronous")


def _volumes(tmp_path, n):
    paths, seeds, cts = [], [], []
    for i in range(n):
        ct, seed, _ = wscg.volseg.make_fractured_shell_phantom(SHAPE, n_fragments=3, seed=i)
        p = tmp_path / f"ct{i}.nii.gz"
        wscg.math.save_volume(p, ct, spacing=(1.0, 0.8, 0.8))
        s = tmp_path / f"ct{i}_seeds.npy"
        np.save(s, seed)
        paths.append(str(p))
        seeds.append(str(s))
        cts.append(ct)
    return paths, seeds


def _files(root: pathlib.Path):
    """The bytes of every output file under ``root`` but the records (they hold timings)."""
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file() and not p.name.endswith(".json") and p.name != "summary.csv"}


def test_importing_wscg_imports_no_dask():
    code = "import sys, wscg, wscg.distributed; sys.exit('dask' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_missing_dask_names_the_extra(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "dask", None)
    with pytest.raises(ImportError, match=r"wscg\[dask\]"):
        wd.reconstruct_mri([np.zeros((8, 8), complex)], [np.ones((8, 8), bool)])


def test_bad_arguments_are_named(tmp_path):
    with pytest.raises(ValueError, match="`paths`"):
        wd.split_bones("one.nii.gz", [None], tmp_path)
    with pytest.raises(ValueError, match="`paths` and `seeds`"):
        wd.split_bones(["a.nii.gz"], [], tmp_path)
    with pytest.raises(ValueError, match="`out_dir`"):
        wd.split_bones(["a.nii.gz"], [None], None)
    with pytest.raises(TypeError, match="`gallery`"):
        wd.identify([np.zeros(3)], object())
    with pytest.raises(ValueError, match="`n_threads`"):
        wd.complete_videos([np.zeros((2, 8, 8, 3), np.uint8)], [np.zeros((2, 8, 8))],
                           tmp_path, n_threads=0)
    with pytest.raises(ValueError, match="`priors`"):
        wd.reconstruct_mri([np.zeros((8, 8), complex)], [np.ones((8, 8))], priors=[])


def test_split_bones_equals_the_sequential_loop(client, tmp_path):
    paths, seeds = _volumes(tmp_path, 3)
    out = tmp_path / "cluster"
    table = wd.split_bones(paths, seeds, out, client=client, params={"max_iter": 400})
    assert list(table["case"]) == ["ct0", "ct1", "ct2"]
    assert not table["skipped"].any()
    assert (table["n_voxels"] == np.prod(SHAPE)).all()
    assert (table["n_meshes"] == table["n_labels"]).all()
    for path, seed, row in zip(paths, seeds, table.itertuples()):
        vol = wscg.math.load_volume(path)
        ref, report = wscg.volseg.random_walker_bone(vol.volume, np.load(seed),
                                                     spacing=vol.spacing, max_iter=400,
                                                     return_report=True)
        got = wscg.math.load_volume(row.labels_path).volume
        np.testing.assert_array_equal(got, ref)
        assert row.n_iter == sum(report.n_iter) and row.n_labels == report.n_labels
        # The mesh of each label lies on that label's voxels, in the file's world frame.
        mesh = wscg.math.load_mesh(out / row.case / f"bone_{report.labels[0]}.ply")
        assert len(mesh.faces) > 0
    # The sequential loop: the same pipeline in this process, one case after another.
    seq = tmp_path / "sequential"
    with _no_default_client(client):
        wd.split_bones(paths, seeds, seq, client=None, params={"max_iter": 400})
    assert _files(out) == _files(seq) and len(_files(out)) >= 3 * 3
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary["case"]) == ["ct0", "ct1", "ct2"]
    # A re-run skips every finished case and changes no file.
    before = _files(out)
    again = wd.split_bones(paths, seeds, out, client=client, params={"max_iter": 400})
    assert again["skipped"].all() and _files(out) == before
    pd.testing.assert_frame_equal(again.drop(columns="skipped"),
                                  table.drop(columns="skipped"))


def test_a_killed_worker_loses_no_finished_case(client, tmp_path):
    paths, seeds = _volumes(tmp_path, 6)
    out = tmp_path / "out"
    pids = client.run(os.getpid)
    result = {}

    def run():
        try:
            result["table"] = wd.split_bones(paths, seeds, out, client=client, meshes=False,
                                             params={"max_iter": 400})
        except Exception as e:  # noqa: BLE001 - reported below
            result["error"] = e

    t = threading.Thread(target=run)
    t.start()
    deadline = time.monotonic() + 60
    while not list(out.glob("*/done.json")) and time.monotonic() < deadline:
        time.sleep(0.02)
    finished = {p.parent.name: p.read_bytes() for p in out.glob("*/done.json")}
    labels = {n: (out / n / "labels.nii.gz").read_bytes() for n in finished}
    assert finished, "no case finished within 60 s"
    os.kill(next(iter(pids.values())), signal.SIGKILL)
    t.join(120)
    assert not t.is_alive()
    if "error" in result:
        # The run may fail with the worker (KilledWorker); the re-run completes it.
        result["table"] = wd.split_bones(paths, seeds, out, client=client, meshes=False,
                                         params={"max_iter": 400})
    table = result["table"]
    assert len(table) == 6
    # The cases finished before the kill are intact (their record and labels unchanged).
    for n, record in finished.items():
        assert (out / n / "done.json").read_bytes() == record
        assert (out / n / "labels.nii.gz").read_bytes() == labels[n]
    again = wd.split_bones(paths, seeds, out, client=client, meshes=False,
                           params={"max_iter": 400})
    assert again["skipped"].all()
    seq = tmp_path / "sequential"
    with _no_default_client(client):
        wd.split_bones(paths, seeds, seq, client=None, meshes=False,
                       params={"max_iter": 400})
    assert _files(out) == _files(seq)
    client.wait_for_workers(2, timeout=60)


def _ears():
    data = wscg.ear.make_ears(n_subjects=8, n_probes=2, seed=3)
    matcher = wscg.ear.EarMatcher().fit(wscg.ear.enroll_many(data.enrol))
    return matcher, data


def test_identify_ears_equals_the_sequential_loop(client):
    matcher, data = _ears()
    table = wd.identify(list(data.probes), matcher, client=client, top_k=3, n_partitions=4)
    rows = []
    for i, probe in enumerate(data.probes):
        res = matcher.identify(probe)
        if res.rejected:
            rows.append((i, 0, None, True))
            continue
        for r in range(3):
            rows.append((i, r + 1, int(res.order[r]), False))
            assert table[(table.probe == i) & (table["rank"] == r + 1)].score.item() \
                == res.scores[r]
    got = [(int(p), int(r), None if ident is None or (isinstance(ident, float)
                                                       and np.isnan(ident)) else int(ident),
            bool(rej)) for p, r, ident, rej in
           table[["probe", "rank", "identity", "rejected"]].itertuples(index=False)]
    assert got == rows
    # Labels name the templates.
    names = [f"subject{i}" for i in range(len(data.enrol))]
    named = wd.identify(list(data.probes[:2]), matcher, client=client, top_k=1, labels=names)
    first = matcher.identify(data.probes[0])
    if not first.rejected:
        assert named.identity.iloc[0] == names[first.order[0]]


def test_identify_gait_and_fdkeca_equal_the_sequential_loop(client):
    walks = wscg.gait.make_walkers(n_subjects=4, n_sessions=2, seed=1)
    train = [f for f, s in zip(walks.frames, walks.sessions) if s == 0]
    y = [l for l, s in zip(walks.labels, walks.sessions) if s == 0]
    probes = [f for f, s in zip(walks.frames, walks.sessions) if s == 1]
    gait = wscg.gait.GaitRecognizer().fit(train, y)
    table = wd.identify(probes, gait, client=client, top_k=2)
    for i, p in enumerate(probes):
        labels, deltas = gait.rank(p)
        part = table[table.probe == i].sort_values("rank")
        assert list(part.identity) == list(labels[:2])
        assert list(part.score) == list(deltas[:2])
    X, y = wscg.biometrics.make_finger_veins(n_subjects=12, n_per_subject=4, seed=2)
    model = wscg.biometrics.FDKECA(n_components=10).fit(X[::2], y[::2])
    table = wd.identify(list(X[1::2]), model, client=client)
    dist, _ = model.kneighbors(X[1::2])
    assert list(table.identity) == list(model.predict(X[1::2]))
    np.testing.assert_array_equal(table.score.to_numpy(), dist)


def _predict(model, X):
    return model.predict(X)


def test_a_model_pickled_here_predicts_identically_in_a_worker(client):
    X, y = wscg.biometrics.make_finger_veins(n_subjects=10, n_per_subject=4, seed=5)
    model = wscg.biometrics.FDKECA(n_components=8).fit(X[::2], y[::2])
    remote = client.submit(_predict, model, X[1::2]).result()
    np.testing.assert_array_equal(remote, model.predict(X[1::2]))
    walks = wscg.gait.make_walkers(n_subjects=3, n_sessions=2, seed=4)
    gait = wscg.gait.GaitRecognizer().fit(walks.frames[::2], walks.labels[::2])
    remote = client.submit(_predict, gait, walks.frames[1::2]).result()
    np.testing.assert_array_equal(remote, gait.predict(walks.frames[1::2]))


def test_complete_videos_equals_the_sequential_loop(client, tmp_path):
    clips, masks = [], []
    for i, kind in enumerate(("sprite", "pan", "sprite")):
        _, observed, mask = wscg.video.make_clip(kind, n_frames=5, height=36, width=48,
                                                 radius=6.0, hole=(8, 10), seed=i)
        p = tmp_path / f"clip{i}.npy"
        np.save(p, observed)
        clips.append(str(p))
        masks.append(mask)
    out = tmp_path / "cluster"
    table = wd.complete_videos(clips, masks, out, client=client,
                               params={"lowres_width": 48, "seed": 7})
    assert list(table.n_frames) == [5, 5, 5]
    for clip, mask, row in zip(clips, masks, table.itertuples()):
        ref = wscg.video.complete_video(np.load(clip), mask, lowres_width=48, seed=7)
        np.testing.assert_array_equal(wscg.video.load_frames(row.frames_path), ref)
    seq = tmp_path / "sequential"
    with _no_default_client(client):
        wd.complete_videos(clips, masks, seq, params={"lowres_width": 48, "seed": 7})
    assert _files(out) == _files(seq)


def test_reconstruct_mri_equals_the_sequential_loop(client, tmp_path):
    n = 32
    image = wscg.csmri.make_shepp_logan_image(n)
    stack = np.stack([image, image[::-1], image.T])
    mask, _ = wscg.csmri.mask_pseudo_radial((n, n), rate=0.4)
    kspace = np.stack([wscg.csmri.simulate(s, mask) for s in stack])
    kpath = tmp_path / "scan.npy"
    np.save(kpath, kspace)
    priors = ("udct", "db4")
    table = wd.reconstruct_mri([str(kpath)], [mask], client=client, priors=priors,
                               params={"max_iter": 8})
    assert len(table) == 3 * 2
    for row in table.itertuples():
        ref = wscg.csmri.reconstruct(kspace[row.slice], mask, prior=row.prior, max_iter=8)
        np.testing.assert_array_equal(row.image, ref)
    out = tmp_path / "cluster"
    written = wd.reconstruct_mri([str(kpath)], [mask], out, client=client, priors=priors,
                                 params={"max_iter": 8})
    for row, ref in zip(written.itertuples(), table.itertuples()):
        np.testing.assert_array_equal(np.load(row.path), ref.image)
    again = wd.reconstruct_mri([str(kpath)], [mask], out, client=client, priors=priors,
                               params={"max_iter": 8})
    assert again["skipped"].all()
    assert list(again.path) == list(written.path)


def test_a_task_removes_only_its_own_leftover_temporary_files(tmp_path):
    # The slices of one scan write into one folder at the same time: a slice re-run after a
    # killed worker removes the temporary files of its own outputs, never another slice's
    # (which another worker may be writing). Names follow the atomic writer's rule
    # (wscg_math::io::atomic::temp_tag, whose unit test checks the same tags).
    assert wd._temp_tag("labels.nii.gz") == "labels-nii-gz"
    assert wd._temp_tag("0001_udct.npy") == "0001_udct-npy"
    assert wd._temp_tag("é x") == "--x"
    assert len(wd._temp_tag("a" * 300)) == 96
    scan = tmp_path / "out" / "kspace_00000"  # the case name of an array entry
    scan.mkdir(parents=True)
    own = [scan / "wscg_tmp_0000_db4-npy_4242_0.tmp", scan / "wscg_tmp_0000_db4-json_4242_1.tmp"]
    other = [scan / "wscg_tmp_0001_db4-npy_4243_0.tmp", scan / "wscg_tmp_0000_db4-npy-x_1_2.tmp"]
    for p in own + other:
        p.write_bytes(b"half")
    kspace = wscg.csmri.simulate(wscg.csmri.make_shepp_logan_image(16), np.ones((16, 16)))
    with dask.config.set(scheduler="synchronous"):
        table = wd.reconstruct_mri([kspace], [np.ones((16, 16))], tmp_path / "out",
                                   priors=["db4"], params={"max_iter": 1})
    assert list(table["kspace"]) == [scan.name] and table["path"][0].endswith("0000_db4.npy")
    assert not any(p.exists() for p in own)
    assert all(p.exists() for p in other)
    # A folder of one case (split_bones, complete_videos) is cleared of every leftover.
    case = wd._Case(tmp_path / "out", scan.name)
    case.discard_partial()
    assert not any(p.exists() for p in other)


def test_workers_size_their_pools_to_their_threads(client):
    wd.reconstruct_mri([np.zeros((16, 16), complex)], [np.ones((16, 16))], client=client,
                       priors=["db4"], params={"max_iter": 1})
    assert set(client.run(wscg.get_num_threads).values()) == {1}
    wd.reconstruct_mri([np.zeros((16, 16), complex)], [np.ones((16, 16))], client=client,
                       priors=["db4"], params={"max_iter": 1}, n_threads=2)
    assert set(client.run(wscg.get_num_threads).values()) <= {1, 2}
    # Back to the workers' own thread count.
    wd.reconstruct_mri([np.zeros((16, 16), complex)] * 4, [np.ones((16, 16))] * 4,
                       client=client, priors=["db4"], params={"max_iter": 1})
    assert set(client.run(wscg.get_num_threads).values()) == {1}


def test_urls_through_fsspec(tmp_path):
    fsspec = pytest.importorskip("fsspec")
    fs = fsspec.filesystem("memory")
    ct, seeds, _ = wscg.volseg.make_fractured_shell_phantom((20, 20, 20), n_fragments=2, seed=9)
    wscg.math.save_volume(tmp_path / "a.nii.gz", ct)
    fs.put(str(tmp_path / "a.nii.gz"), "/in/a.nii.gz")
    with fs.open("/in/a_seeds.npy", "wb") as f:
        np.save(f, seeds)
    with dask.config.set(scheduler="synchronous"):
        table = wd.split_bones(["memory://in/a.nii.gz"], ["memory://in/a_seeds.npy"],
                               "memory://out", meshes=True)
    assert table.labels_path[0] == "memory://out/a/labels.nii.gz"
    assert fs.exists("/out/a/done.json") and fs.exists("/out/summary.csv")
    with fs.open("/out/a/labels.nii.gz", "rb") as f:
        (tmp_path / "back.nii.gz").write_bytes(f.read())
    ref = wscg.volseg.random_walker_bone(ct, seeds)
    np.testing.assert_array_equal(wscg.math.load_volume(tmp_path / "back.nii.gz").volume, ref)
    record = json.loads(fs.cat("/out/a/done.json"))
    assert record["case"] == "a"
    with dask.config.set(scheduler="synchronous"):
        again = wd.split_bones(["memory://in/a.nii.gz"], ["memory://in/a_seeds.npy"],
                               "memory://out")
    assert again.skipped.all()


def test_arrays_on_unaligned_buffers_are_read():
    """Dask (pickle protocol 5) rebuilds arrays on the buffers it receives, which need not
    be aligned for their dtype; the bindings copy such arrays instead of failing."""
    walks = wscg.gait.make_walkers(n_subjects=2, n_sessions=1, seed=0)
    frames = walks.frames[0]
    buf = bytearray(frames.nbytes + 1)
    unaligned = np.frombuffer(buf, dtype=np.float64, offset=1).reshape(frames.shape)
    unaligned[...] = frames
    assert not unaligned.flags.aligned
    a, b = frames[:, 0, 0].copy(), frames[:, 1, 0].copy()
    ua = np.frombuffer(bytearray(a.nbytes + 3), dtype=np.float64, offset=3)
    ua[...] = a
    assert wscg.gait.dtw(ua, b) == wscg.gait.dtw(a, b)
    gait = wscg.gait.GaitRecognizer().fit(walks.frames, walks.labels)
    for x, y in zip(gait.rank(unaligned), gait.rank(frames)):
        np.testing.assert_array_equal(x, y)
    # A strided view of unaligned memory.
    plane = np.frombuffer(bytearray(8 * 200 + 5), dtype=np.float64, offset=5).reshape(10, 20)
    plane[...] = np.arange(200.0).reshape(10, 20) ** 1.5
    view = plane[::2, ::-1]
    assert not view.flags.aligned and not view.flags.c_contiguous
    np.testing.assert_array_equal(wscg.math.gaussian_filter(view, 1.5),
                                  wscg.math.gaussian_filter(np.ascontiguousarray(view), 1.5))
