"""Batch pipelines on Dask: many volumes, probes, clips or MRI slices across worker processes
and machines (optional: ``pip install 'wscg[dask]'``).

Four ready pipelines, one Dask task per case:

- :func:`split_bones`: BoneSplit (paper 18) per CT volume (NIfTI file or DICOM folder), the
  label volume and one mesh per bone written per case, one summary table;
- :func:`identify`: ear (paper 14), gait (paper 17) or FDKECA (paper 01) identification
  against a fitted gallery model that is sent to each worker once, the probes split into
  partitions; the ranked results as one table;
- :func:`complete_videos`: video completion (paper 06) per clip;
- :func:`reconstruct_mri`: compressed-sensing MRI (paper 11) per slice and prior.

Each takes ``client``: a ``distributed.Client`` (a ``LocalCluster`` on a laptop, a
``dask-scheduler`` with ``dask-worker`` processes on several machines, Ray through
``ray.util.dask``), or ``None`` for Dask's default scheduler (the current ``Client`` if one
exists, else Dask's local threads). Progress shows on the Dask dashboard and, with
``progress=True``, in Dask's progress bar. Tables are pandas ``DataFrame`` objects, also
written as ``summary.csv`` under ``out_dir``.

Threads: a worker process runs its tasks with the wscg thread pool sized to the worker's
number of Dask threads (``threads_per_worker``), or to ``n_threads`` when given, so that N
single-threaded workers on N cores do not each start N threads (see
:func:`wscg.set_num_threads`).

Files: inputs and ``out_dir`` are local paths or URLs that fsspec resolves (``s3://...``,
``gs://...``, ``file://...``; fsspec is only needed for URLs). Every output is written
atomically, and each case ends by writing a small ``done.json`` record: a re-run (after a
worker or the whole cluster was lost) skips the cases already finished, unless
``overwrite=True``. The results equal those of the sequential loop over the same cases
(the methods are deterministic for a given seed, with any thread count).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import posixpath
import re
import shutil
import tempfile
import time
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ._checks import ArgumentTypeError
from ._checks import _kind as _describe
from ._checks import integer_ranges as _integer_ranges

__all__ = ["split_bones", "identify", "complete_videos", "reconstruct_mri"]

_EXTRA = "pip install 'wscg[dask]'"

# The record each case writes last; its presence marks the case as finished.
_DONE = "done.json"


def _require(module: str):
    """Imports an optional dependency, or raises an ImportError that names the extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(
            f"wscg.distributed needs {module.split('.')[0]} (dask[distributed] and pandas): "
            f"{_EXTRA}") from e


# ---------------------------------------------------------------------------------------
# Paths and URLs


def _is_url(path) -> bool:
    return isinstance(path, str) and "://" in path and not path.startswith("file://")


def _plain(path) -> str:
    text = os.fspath(path)
    return text[len("file://"):] if text.startswith("file://") else text


def _name(path) -> str:
    """The case name of an input: its file name without the volume/array extensions."""
    base = posixpath.basename(_plain(path).rstrip("/\\").replace("\\", "/"))
    for ext in (".nii.gz", ".nii", ".npy", ".npz", ".csv", ".png", ".jpg", ".dcm"):
        if base.lower().endswith(ext):
            return base[: -len(ext)]
    return base


@contextlib.contextmanager
def _local(path) -> Iterator[str]:
    """A local path for ``path``: itself, or a temporary copy of a URL's file or folder."""
    if not _is_url(path):
        yield _plain(path)
        return
    fsspec = _require("fsspec")
    fs, remote = fsspec.core.url_to_fs(path)
    with tempfile.TemporaryDirectory(prefix="wscg-in-") as tmp:
        local = os.path.join(tmp, posixpath.basename(remote.rstrip("/")) or "input")
        fs.get(remote, local, recursive=fs.isdir(remote))
        yield local


class _Case:
    """The output folder of one case: files are written locally (atomically) and, for a URL
    ``out_dir``, uploaded when the case finishes; ``done.json`` is written last."""

    def __init__(self, out_dir, name: str, marker: str = _DONE):
        self.marker = marker
        self.url = _is_url(out_dir)
        if self.url:
            fsspec = _require("fsspec")
            self.fs, root = fsspec.core.url_to_fs(out_dir)
            self.remote = posixpath.join(root, name)
            self._tmp = tempfile.mkdtemp(prefix="wscg-out-")
            self.dir = self._tmp
        else:
            self.dir = os.path.join(_plain(out_dir), name)
            os.makedirs(self.dir, exist_ok=True)
        self.location = (posixpath.join(str(out_dir).rstrip("/"), name) if self.url
                         else self.dir)

    def path(self, file: str) -> str:
        return os.path.join(self.dir, file)

    def where(self, file: str) -> str:
        """Where ``file`` ends up (a URL for a URL ``out_dir``)."""
        return posixpath.join(self.location, file) if self.url else self.path(file)

    def done(self) -> Optional[Dict[str, Any]]:
        """The record of a finished case, or None."""
        try:
            if self.url:
                target = posixpath.join(self.remote, self.marker)
                if not self.fs.exists(target):
                    return None
                with self.fs.open(target, "rb") as f:
                    return json.loads(f.read())
            with open(self.path(self.marker), "rb") as f:
                return json.loads(f.read())
        except (OSError, ValueError):
            return None

    def discard_partial(self, files: Optional[Sequence[str]] = None) -> None:
        """Removes the temporary files of writes that a killed worker left half done in this
        case's folder, before the case runs again: every ``wscg_tmp_*`` file, or, where
        several tasks write into one folder, only those of the destinations ``files`` (the
        writer names them ``wscg_tmp_<tag>_<pid>_<n>.<ext>``, :func:`_temp_tag`), so that a
        task never removes a file another task is writing."""
        if files is None:
            wanted = re.compile(r"wscg_tmp_")
        else:
            wanted = re.compile("|".join(rf"wscg_tmp_{re.escape(_temp_tag(f))}_\d+_\d+\."
                                         for f in files))
        for root, _, names in os.walk(self.dir):
            for n in names:
                if wanted.match(n):
                    try:
                        os.remove(os.path.join(root, n))
                    except OSError:
                        pass

    def finish(self, record: Dict[str, Any]) -> None:
        """Writes the record, after the outputs (uploaded first for a URL)."""
        _write_bytes(self.path(self.marker), json.dumps(record, sort_keys=True).encode())
        if self.url:
            try:
                names = sorted(os.listdir(self.dir), key=lambda n: n == self.marker)
                for n in names:  # the record last
                    self.fs.put(self.path(n), posixpath.join(self.remote, n),
                                recursive=os.path.isdir(self.path(n)))
            finally:
                shutil.rmtree(self._tmp, ignore_errors=True)


def _temp_tag(file_name: str) -> str:
    """The tag of destination ``file_name`` in the names of the temporary files that wscg's
    atomic writes use (``wscg_math::io::atomic::temp_tag``): every character other than an
    ASCII letter, digit, ``_`` or ``-`` replaced by ``-``, at most 96 characters."""
    return re.sub(r"[^A-Za-z0-9_-]", "-", file_name)[:96]


def _write_bytes(path: str, data: bytes) -> None:
    from ._native import math as _m

    _m.write_file(path, data)


def _save_npy(path: str, array: np.ndarray) -> None:
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(array), allow_pickle=False)
    _write_bytes(path, buf.getvalue())


def _load_array(path) -> np.ndarray:
    with _local(path) as p:
        return np.load(p, allow_pickle=False)


def _write_table(out_dir, frame) -> None:
    """``summary.csv`` under ``out_dir`` (atomic)."""
    data = frame.to_csv(index=False).encode()
    if _is_url(out_dir):
        fsspec = _require("fsspec")
        fs, root = fsspec.core.url_to_fs(out_dir)
        with fs.open(posixpath.join(root, "summary.csv"), "wb") as f:
            f.write(data)
    else:
        os.makedirs(_plain(out_dir), exist_ok=True)
        _write_bytes(os.path.join(_plain(out_dir), "summary.csv"), data)


# ---------------------------------------------------------------------------------------
# Running tasks


def _threads(n_threads: Optional[int]) -> None:
    """Sizes this process's wscg pool: ``n_threads`` if given, else, inside a Dask worker,
    the worker's number of threads; elsewhere the process's setting stays."""
    import wscg

    if n_threads is None:
        try:
            from distributed import get_worker

            n_threads = get_worker().state.nthreads
        except (ImportError, ValueError, AttributeError):
            return
    if wscg.get_num_threads() != n_threads:
        wscg.set_num_threads(n_threads)


def _finished(case: Optional[_Case], overwrite: bool,
              files: Optional[Sequence[str]] = None) -> Optional[Dict[str, Any]]:
    """The record of a case an earlier run finished, or None when the case must run (no
    output folder, ``overwrite``, or not finished; the temporary files of an interrupted
    earlier run are then removed: all of them, or those of the destinations ``files`` when
    other tasks share the folder)."""
    done = None if case is None or overwrite else case.done()
    if done is None and case is not None:
        case.discard_partial(files)
    return done


def _check_threads(n_threads) -> None:
    if n_threads is not None and (isinstance(n_threads, bool) or not isinstance(n_threads, int)
                                  or not 1 <= n_threads <= 1024):
        raise ValueError(f"`n_threads` must be None or a thread count in 1..=1024, "
                         f"got {n_threads!r}")


def _client(client):
    """``client``, else the current default Client (the one Dask's default scheduler
    would use), else None: Dask's local scheduler (``dask.config`` ``scheduler``)."""
    if client is not None:
        return client
    dask = _require("dask")
    if dask.config.get("scheduler", None) not in (None, "dask.distributed", "distributed"):
        return None
    try:
        from distributed import default_client

        return default_client()
    except (ImportError, ValueError):
        return None


def _task(fn, *args):
    """Runs one task; an error that is not an ``Exception`` (pyo3's ``PanicException`` for
    an internal error) becomes a ``RuntimeError``, which Dask reports to the caller (it
    leaves the task hanging on a bare ``BaseException``)."""
    try:
        return fn(*args)
    except (Exception, KeyboardInterrupt, SystemExit, GeneratorExit):
        raise
    except BaseException as e:
        raise RuntimeError(f"{type(e).__name__}: {e}") from None


def _run(tasks: List[Tuple[Callable, tuple]], client, progress: bool) -> List[Any]:
    """Runs ``fn(*args)`` for each task: on a Client as futures (results finished before a
    worker is lost are kept, and its lost tasks run again on the other workers), or through
    ``dask.compute`` on Dask's local scheduler."""
    dask = _require("dask")
    client = _client(client)
    if client is not None:
        futures = [client.submit(_task, fn, *args, pure=False) for fn, args in tasks]
        if progress:
            from distributed import progress as _progress

            _progress(futures)
        return client.gather(futures)
    delayed = [dask.delayed(_task, pure=False)(fn, *args) for fn, args in tasks]
    if progress:
        from dask.diagnostics import ProgressBar

        with ProgressBar():
            return list(dask.compute(*delayed))
    return list(dask.compute(*delayed))


def _frame(rows: List[Dict[str, Any]], columns: Sequence[str]):
    pd = _require("pandas")
    return pd.DataFrame(rows, columns=list(columns))


def _names(items: Sequence[Any], what: str) -> List[str]:
    """Unique case names: file names of paths, ``<what>_<i>`` for arrays."""
    names = [_name(x) if isinstance(x, (str, os.PathLike)) else f"{what}_{i:05d}"
             for i, x in enumerate(items)]
    if len(set(names)) != len(names):
        names = [f"{i:05d}_{n}" for i, n in enumerate(names)]
    return names


def _items(v, name: str) -> list:
    """The entries of a sequence argument (a string or path is refused: one case is a
    list of one)."""
    if v is None or isinstance(v, (str, bytes, os.PathLike)) or (
            isinstance(v, np.ndarray) and v.ndim == 0):
        raise ArgumentTypeError(f"`{name}` must be a sequence (one entry per case), got "
                                f"{_describe(v)}")
    try:
        return list(v)
    except TypeError:
        raise ArgumentTypeError(f"`{name}` must be a sequence (one entry per case), got "
                                f"{_describe(v)}") from None


def _check_dir(v, name: str) -> None:
    if not isinstance(v, (str, os.PathLike)):
        raise ArgumentTypeError(f"`{name}` must be a folder path or URL (str or "
                                f"os.PathLike), got {_describe(v)}")


def _params(params, f, fixed: Sequence[str]) -> Dict[str, Any]:
    """``params`` as keyword arguments of ``f``: a mapping of its parameter names, less the
    ones the pipeline sets itself (``fixed``)."""
    import inspect

    if params is None:
        return {}
    if not isinstance(params, Mapping):
        raise ArgumentTypeError(f"`params` must be a mapping of keyword arguments of "
                                f"{f.__name__}, got {_describe(params)}")
    known = set(inspect.signature(f).parameters) - {"self"}
    for name in params:
        if name in fixed:
            raise ValueError(f"`params` sets {name!r}, which the pipeline sets itself")
        if name not in known:
            raise ValueError(f"`params` names {name!r}, not a parameter of {f.__name__}")
    return dict(params)


def _pairs(a, b, na: str, nb: str) -> Tuple[list, list]:
    a, b = _items(a, na), _items(b, nb)
    if len(a) != len(b):
        raise ValueError(f"`{na}` and `{nb}` must have the same length, got {len(a)} and "
                         f"{len(b)}")
    return a, b


# ---------------------------------------------------------------------------------------
# split_bones

_SPLIT_COLUMNS = ("case", "path", "n_voxels", "n_bone_voxels", "n_labels", "n_iter", "seconds",
                  "labels_path", "n_meshes", "skipped")


def _seed_volume(seeds, shape: Tuple[int, int, int]) -> np.ndarray:
    """A seed label volume from a volume file or URL, an array, or strokes
    ``{label: (n, 3) [z, y, x] indices}``."""
    from . import math as _wm

    if isinstance(seeds, Mapping):
        out = np.zeros(shape, np.uint16)
        for label, zyx in seeds.items():
            idx = np.asarray(zyx, dtype=np.int64).reshape(-1, 3)
            if idx.size and (idx.min() < 0 or np.any(idx >= np.asarray(shape))):
                raise ValueError(f"`seeds` stroke of label {label} leaves the volume {shape}")
            out[idx[:, 0], idx[:, 1], idx[:, 2]] = int(label)
        return out
    if isinstance(seeds, (str, os.PathLike)):
        if _plain(seeds).endswith(".npy"):
            arr = _load_array(seeds)
        else:
            with _local(seeds) as p:
                arr = _wm.load_volume(p).volume
    else:
        arr = np.asarray(seeds)
    if arr.shape != tuple(shape):
        raise ValueError(f"`seeds` has shape {arr.shape}, the volume {tuple(shape)}")
    return np.rint(arr).astype(np.uint16)


def _split_one(path, seeds, out_dir, name, params, meshes, overwrite, n_threads):
    from . import isosurface as _iso
    from . import math as _wm
    from . import volseg as _vs

    case = _Case(out_dir, name)
    done = _finished(case, overwrite)
    if done is not None:
        return dict(done, skipped=True)
    _threads(n_threads)
    start = time.perf_counter()
    with _local(path) as p:
        vol = _wm.load_volume(p)
    ct = vol.volume
    labels, report = _vs.random_walker_bone(ct, _seed_volume(seeds, ct.shape),
                                            spacing=vol.spacing, return_report=True, **params)
    _wm.save_volume(case.path("labels.nii.gz"), labels, affine=vol.affine)
    n_meshes = 0
    if meshes:
        for label in report.labels:
            mask = (labels == label).astype(np.float32)
            if not mask.any():
                continue
            verts, faces, _, _ = _iso.marching_cubes(np.pad(mask, 1), 0.5, normals=None,
                                                     origin=(-1.0, -1.0, -1.0))
            # Voxel indices (x, y, z) to the file's world frame (py/API.md).
            ijk1 = np.c_[verts.astype(np.float64), np.ones(len(verts))]
            world = (ijk1 @ vol.affine.T)[:, :3]
            _wm.save_mesh(case.path(f"bone_{label}.ply"), world, faces)
            n_meshes += 1
    record = {
        "case": name, "path": str(path), "n_voxels": int(ct.size),
        "n_bone_voxels": int(report.n_nodes), "n_labels": int(report.n_labels),
        "n_iter": int(sum(report.n_iter)), "seconds": time.perf_counter() - start,
        "labels_path": case.where("labels.nii.gz"), "n_meshes": n_meshes,
    }
    case.finish(record)
    return dict(record, skipped=False)


def split_bones(paths: Sequence[Any], seeds: Sequence[Any], out_dir: Any, *, client: Any = None,
                meshes: bool = True, n_threads: Optional[int] = None, overwrite: bool = False,
                progress: bool = False, params: Optional[Mapping[str, Any]] = None):
    """BoneSplit (paper 18) on every CT volume of ``paths``, one Dask task per volume.

    Parameters
    ----------
    paths : sequence of path or URL
        CT volumes: NIfTI files or DICOM series folders (:func:`wscg.math.load_volume`),
        in Hounsfield units.
    seeds : sequence, one per path
        The seeds of each volume (paper 18, section 3.2): a label volume (a NIfTI file or
        ``.npy`` path or URL, or an array of the volume's shape; 0 = unlabelled), or strokes
        as a mapping ``{label: (n, 3) voxel indices [z, y, x]}``.
    out_dir : path or URL
        Each case writes ``<out_dir>/<name>/labels.nii.gz`` (uint16, the input's affine),
        ``bone_<label>.ply`` (the marching-cubes surface of each label, in the file's world
        millimetres) and ``done.json``; ``<name>`` is the input's file or folder name.
    client : distributed.Client or None
        Where to run; ``None``: Dask's default scheduler.
    meshes : bool
        Whether to write the per-label meshes.
    n_threads : int or None
        wscg threads per worker process; ``None``: the worker's number of Dask threads.
    overwrite : bool
        Recompute the cases already finished (by default a re-run skips them).
    progress : bool
        Show Dask's progress bar.
    params : mapping or None
        Keyword arguments of :func:`wscg.volseg.random_walker_bone` by name (``t_bone``,
        ``beta``, ``tol``, ``max_iter``, ...). The volume's ``spacing`` comes from its file.

    Returns
    -------
    pandas.DataFrame
        One row per case: ``case``, ``path``, ``n_voxels``, ``n_bone_voxels`` (graph
        nodes), ``n_labels``, ``n_iter`` (CG iterations summed over the labels),
        ``seconds`` (wall time of the case on its worker), ``labels_path``, ``n_meshes``,
        ``skipped`` (finished by an earlier run). Also written as ``<out_dir>/summary.csv``.
    """
    paths, seeds = _pairs(paths, seeds, "paths", "seeds")
    _check_dir(out_dir, "out_dir")
    _check_threads(n_threads)
    from . import volseg as _vs

    params = _params(params, _vs.random_walker_bone, ("spacing", "return_prob", "return_report"))
    names = _names(paths, "case")
    tasks = [(_split_one, (p, s, out_dir, n, params, bool(meshes), bool(overwrite), n_threads))
             for p, s, n in zip(paths, seeds, names)]
    frame = _frame(_run(tasks, client, progress), _SPLIT_COLUMNS)
    _write_table(out_dir, frame)
    return frame


# ---------------------------------------------------------------------------------------
# identify

_IDENTIFY_COLUMNS = ("probe", "rank", "identity", "score", "rejected")


def _gallery_kind(gallery) -> str:
    from . import biometrics as _b
    from . import ear as _ear
    from . import gait as _gait

    if isinstance(gallery, _ear.EarMatcher):
        return "ear"
    if isinstance(gallery, _gait.GaitRecognizer):
        return "gait"
    if isinstance(gallery, _b._Subspace):
        return "subspace"
    raise TypeError("`gallery` must be a fitted wscg.ear.EarMatcher, "
                    "wscg.gait.GaitRecognizer or wscg.biometrics model (FDKECA, PCA, "
                    f"KernelPCA, KECA), got {type(gallery).__name__}")


def _probe_data(probe, kind: str):
    if not isinstance(probe, (str, os.PathLike)):
        return probe
    if _plain(probe).endswith(".npy"):
        return _load_array(probe)
    with _local(probe) as p:
        if kind == "gait":
            from . import gait as _gait

            return _gait.load_skeleton(p)
        from . import math as _wm

        image = _wm.load_image(p)
        return np.clip(np.rint(image * 255.0), 0, 255).astype(np.uint8)


def _identify_part(gallery, probes, ids, kind, top_k, labels, n_threads):
    _threads(n_threads)
    rows: List[Dict[str, Any]] = []
    if kind == "subspace":
        X = np.stack([np.asarray(_probe_data(p, kind), dtype=np.float64).ravel()
                      for p in probes])
        dist, idx = gallery.kneighbors(X)
        ident = gallery.predict(X)
        for pid, d, c in zip(ids, dist, ident):
            rows.append({"probe": pid, "rank": 1, "identity": c.item() if hasattr(c, "item")
                         else c, "score": float(d), "rejected": False})
        return rows
    for pid, probe in zip(ids, probes):
        data = _probe_data(probe, kind)
        if kind == "ear":
            res = gallery.identify(data)
            order, scores, rejected = res.order, res.scores, bool(res.rejected)
            names = order if labels is None else np.asarray(labels)[order]
        else:
            names, scores = gallery.rank(data)
            rejected = False
        for r in range(min(top_k, len(scores))):
            ident = names[r]
            rows.append({"probe": pid, "rank": r + 1,
                         "identity": ident.item() if hasattr(ident, "item") else ident,
                         "score": float(scores[r]), "rejected": rejected})
        if rejected:
            rows.append({"probe": pid, "rank": 0, "identity": None, "score": float("nan"),
                         "rejected": True})
    return rows


def identify(probes: Sequence[Any], gallery: Any, *, client: Any = None, top_k: int = 5,
             labels: Optional[Sequence[Any]] = None, n_partitions: Optional[int] = None,
             n_threads: Optional[int] = None, progress: bool = False):
    """Identifies every probe against a fitted gallery model, the model sent to each worker
    once (scattered) and the probes split into partitions, one Dask task each.

    Parameters
    ----------
    probes : sequence
        Probes: arrays (an RGB ear image, a ``(T, 25, 3)`` Kinect walk, a feature vector for
        the subspace models), or paths/URLs to ``.npy`` files, images (ears) or skeleton
        files (:func:`wscg.gait.load_skeleton`).
    gallery : fitted model
        :class:`wscg.ear.EarMatcher` (paper 14; ranked by index-based matching, rejected
        probes reported), :class:`wscg.gait.GaitRecognizer` (paper 17; ranked by
        ``Delta``) or a model of :mod:`wscg.biometrics` (:class:`~wscg.biometrics.FDKECA`,
        paper 01, and its baselines; the nearest gallery sample, 1-NN).
    client : distributed.Client or None
        Where to run; ``None``: Dask's default scheduler.
    top_k : int
        Ranks kept per probe (ear and gait; the subspace models give rank 1).
    labels : sequence or None
        Identity of each ear template (the matcher's gallery is indexed by template); by
        default the template index.
    n_partitions : int or None
        Number of probe partitions (tasks); ``None``: four per worker thread, at most one
        per probe.
    n_threads : int or None
        wscg threads per worker process; ``None``: the worker's number of Dask threads.
    progress : bool
        Show Dask's progress bar.

    Returns
    -------
    pandas.DataFrame
        One row per probe and rank: ``probe`` (the probe's path, or its index), ``rank``
        (1 = best), ``identity``, ``score`` (ear: the match score, larger is better; gait:
        ``Delta``; subspace: the distance, smaller is better), ``rejected`` (an ear probe
        too occluded to rank: one row of rank 0).
    """
    kind = _gallery_kind(gallery)
    _check_threads(n_threads)
    if isinstance(top_k, bool) or not isinstance(top_k, int) or top_k < 1:
        raise ValueError(f"`top_k` must be an int >= 1, got {top_k!r}")
    probes = _items(probes, "probes")
    ids = [str(p) if isinstance(p, (str, os.PathLike)) else i for i, p in enumerate(probes)]
    if not probes:
        return _frame([], _IDENTIFY_COLUMNS)
    if labels is not None:
        labels = list(labels)
    if n_partitions is None:
        n_partitions = 4 * _total_threads(client)
    if isinstance(n_partitions, bool) or not isinstance(n_partitions, int) or n_partitions < 1:
        raise ValueError(f"`n_partitions` must be an int >= 1, got {n_partitions!r}")
    n_partitions = min(n_partitions, len(probes))
    bounds = np.linspace(0, len(probes), n_partitions + 1).round().astype(int)
    client = _client(client)
    # hash=False: a fresh key per call (a repeated call must not race the release of
    # the previous call's copy of the same model).
    model = (client.scatter(gallery, broadcast=True, hash=False) if client is not None
             else gallery)
    tasks = [(_identify_part, (model, probes[a:b], ids[a:b], kind, top_k, labels, n_threads))
             for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
    parts = _run(tasks, client, progress)
    return _frame([row for part in parts for row in part], _IDENTIFY_COLUMNS)


def _total_threads(client) -> int:
    client = _client(client)
    if client is None:
        return os.cpu_count() or 1
    return max(1, sum(client.nthreads().values()))


# ---------------------------------------------------------------------------------------
# complete_videos

_VIDEO_COLUMNS = ("clip", "path", "n_frames", "height", "width", "n_hole_pixels", "energy",
                  "seconds", "frames_path", "skipped")


def _clip_data(clip) -> np.ndarray:
    from . import video as _video

    if not isinstance(clip, (str, os.PathLike)):
        return np.asarray(clip)
    if _plain(clip).endswith(".npy"):
        return _load_array(clip)
    with _local(clip) as p:
        return _video.load_frames(p)


def _mask_data(mask, shape) -> np.ndarray:
    from . import video as _video

    if not isinstance(mask, (str, os.PathLike)):
        return np.asarray(mask)
    if _plain(mask).endswith(".npy"):
        return _load_array(mask)
    with _local(mask) as p:
        return _video.load_mask(p, shape[0], shape[1], shape[2])


def _complete_one(clip, mask, out_dir, name, params, overwrite, n_threads):
    from . import video as _video

    case = _Case(out_dir, name)
    done = _finished(case, overwrite)
    if done is not None:
        return dict(done, skipped=True)
    _threads(n_threads)
    start = time.perf_counter()
    frames = _clip_data(clip)
    hole = _mask_data(mask, frames.shape)
    out, stats = _video.complete_video(frames, hole, return_stats=True, **params)
    _video.save_frames(case.path("frames"), out)
    record = {
        "clip": name, "path": str(clip) if isinstance(clip, (str, os.PathLike)) else None,
        "n_frames": int(out.shape[0]), "height": int(out.shape[1]), "width": int(out.shape[2]),
        "n_hole_pixels": int(np.count_nonzero(hole)), "energy": float(stats.energy),
        "seconds": time.perf_counter() - start, "frames_path": case.where("frames"),
    }
    case.finish(record)
    return dict(record, skipped=False)


def complete_videos(clips: Sequence[Any], masks: Sequence[Any], out_dir: Any, *,
                    client: Any = None, n_threads: Optional[int] = None,
                    overwrite: bool = False, progress: bool = False,
                    params: Optional[Mapping[str, Any]] = None):
    """Video completion (paper 06, :func:`wscg.video.complete_video`) of every clip, one
    Dask task per clip.

    Parameters
    ----------
    clips : sequence
        Clips: folders of frames (:func:`wscg.video.load_frames`), ``.npy`` files or
        ``(F, H, W, 3)`` uint8 arrays.
    masks : sequence, one per clip
        Hole masks: an image or folder (:func:`wscg.video.load_mask`), a ``.npy`` file or an
        ``(F, H, W)`` array (non-zero = hole).
    out_dir : path or URL
        Each clip writes ``<out_dir>/<name>/frames/frame_00000.png``, ... and ``done.json``.
    client, n_threads, overwrite, progress
        As in :func:`split_bones`.
    params : mapping or None
        Keyword arguments of :func:`wscg.video.complete_video` by name (``seed``,
        ``patch``, ``lowres_width``, ...).

    Returns
    -------
    pandas.DataFrame
        One row per clip: ``clip``, ``path``, ``n_frames``, ``height``, ``width``,
        ``n_hole_pixels``, ``energy`` (the final completion energy), ``seconds``,
        ``frames_path``, ``skipped``. Also written as ``<out_dir>/summary.csv``.
    """
    clips, masks = _pairs(clips, masks, "clips", "masks")
    _check_dir(out_dir, "out_dir")
    _check_threads(n_threads)
    from . import video as _video

    params = _params(params, _video.complete_video, ("return_stats", "return_matches"))
    names = _names(clips, "clip")
    tasks = [(_complete_one, (c, m, out_dir, n, params, bool(overwrite), n_threads))
             for c, m, n in zip(clips, masks, names)]
    frame = _frame(_run(tasks, client, progress), _VIDEO_COLUMNS)
    _write_table(out_dir, frame)
    return frame


# ---------------------------------------------------------------------------------------
# reconstruct_mri

_MRI_COLUMNS = ("kspace", "slice", "prior", "n_iter", "seconds", "path", "image", "skipped")


def _slices(x, what: str) -> List[np.ndarray]:
    arr = _load_array(x) if isinstance(x, (str, os.PathLike)) else np.asarray(x)
    if arr.ndim == 2:
        return [arr]
    if arr.ndim == 3:
        return list(arr)
    raise ValueError(f"`{what}` entries must be 2-D slices or 3-D stacks of slices, got "
                     f"shape {arr.shape}")


def _mri_one(kspace, mask, out_dir, name, index, prior, params, overwrite, n_threads):
    from . import csmri as _cs

    file = f"{index:04d}_{prior}"
    case = _Case(out_dir, name, f"{file}.json") if out_dir is not None else None
    # The slices and priors of one scan share its folder: only this task's files are its own.
    done = _finished(case, overwrite, [f"{file}.npy", f"{file}.json"])
    if done is not None:
        return dict(done, image=None, skipped=True)
    _threads(n_threads)
    start = time.perf_counter()
    image, history = _cs.reconstruct(kspace, mask, prior=prior, return_history=True, **params)
    record = {"kspace": name, "slice": index, "prior": prior, "n_iter": int(history.n_iter),
              "seconds": time.perf_counter() - start, "path": None}
    if case is None:
        return dict(record, image=image, skipped=False)
    record["path"] = case.where(f"{file}.npy")
    _save_npy(case.path(f"{file}.npy"), image)
    case.finish(record)
    return dict(record, image=None, skipped=False)


def reconstruct_mri(kspaces: Sequence[Any], masks: Sequence[Any], out_dir: Any = None, *,
                    priors: Sequence[str] = ("udct",), client: Any = None,
                    n_threads: Optional[int] = None, overwrite: bool = False,
                    progress: bool = False, params: Optional[Mapping[str, Any]] = None):
    """Compressed-sensing MRI reconstruction (paper 11, :func:`wscg.csmri.reconstruct`) of
    every slice with every prior, one Dask task per slice and prior.

    Parameters
    ----------
    kspaces : sequence
        Undersampled k-space: complex ``(H, W)`` slices or ``(n_slices, H, W)`` stacks
        (arrays, or paths/URLs of ``.npy`` files), as :func:`wscg.csmri.reconstruct` takes.
    masks : sequence, one per entry of ``kspaces``
        The sampling masks: an ``(H, W)`` mask shared by the slices, or one per slice.
    out_dir : path, URL or None
        Each slice writes ``<out_dir>/<name>/<slice>_<prior>.npy`` (complex128) and its
        record ``<slice>_<prior>.json``; ``None`` returns the images in the table instead.
    priors : sequence of str
        Priors of :func:`wscg.csmri.reconstruct` (``"udct"``, ``"fdct"``, ``"lrsflct"``,
        ``"mrsflct"``, ``"db1"`` ... ``"db8"``, ``"identity"``).
    client, n_threads, overwrite, progress
        As in :func:`split_bones`.
    params : mapping or None
        Other keyword arguments of :func:`wscg.csmri.reconstruct` by name (``max_iter``,
        ``tol``, ...).

    Returns
    -------
    pandas.DataFrame
        One row per slice and prior: ``kspace`` (the entry's name), ``slice``, ``prior``,
        ``n_iter``, ``seconds``, ``path`` (the written file), ``image`` (the
        reconstruction when ``out_dir`` is None, else None), ``skipped``. With ``out_dir``,
        also written as ``<out_dir>/summary.csv`` (without the images).
    """
    kspaces, masks = _pairs(kspaces, masks, "kspaces", "masks")
    if out_dir is not None:
        _check_dir(out_dir, "out_dir")
    _check_threads(n_threads)
    priors = [priors] if isinstance(priors, str) else list(priors)
    if not priors or not all(isinstance(p, str) for p in priors):
        raise ValueError(f"`priors` must be a non-empty sequence of prior names, got {priors!r}")
    from . import csmri as _cs

    params = _params(params, _cs.reconstruct, ("prior", "return_history"))
    names = _names(kspaces, "kspace")
    tasks = []
    for k, m, name in zip(kspaces, masks, names):
        ks = _slices(k, "kspaces")
        ms = _slices(m, "masks")
        if len(ms) == 1:
            ms = ms * len(ks)
        if len(ms) != len(ks):
            raise ValueError(f"`masks` entry of {name} has {len(ms)} slices, its k-space "
                             f"{len(ks)}")
        for i, (kslice, mslice) in enumerate(zip(ks, ms)):
            for prior in priors:
                tasks.append((_mri_one, (kslice, mslice, out_dir, name, i, prior, params,
                                         bool(overwrite), n_threads)))
    frame = _frame(_run(tasks, client, progress), _MRI_COLUMNS)
    if out_dir is not None:
        _write_table(out_dir, frame.drop(columns=["image"]))
    return frame


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
