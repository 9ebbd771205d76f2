"""Rust log records reach Python's `logging` under the `wscg` logger."""

from __future__ import annotations

import logging
import os
import threading

import numpy as np
import pytest

import wscg


def _records(caplog, name_prefix="wscg"):
    return [r for r in caplog.records if r.name == name_prefix or r.name.startswith(name_prefix + ".")]


def test_solver_records_arrive_from_worker_threads_at_their_level(caplog):
    # The random walker runs on the pool's worker threads; its summary is an INFO record of
    # the logger wscg.volseg.walker.
    vol = np.zeros((8, 10, 12), np.float32)
    vol[:, :, 2:5] = 1000.0
    vol[:, :, 7:10] = 1000.0
    seeds = np.zeros(vol.shape, np.int32)
    seeds[4, 5, 3] = 1
    seeds[4, 5, 8] = 2
    with caplog.at_level(logging.INFO, logger="wscg"):
        wscg.volseg.random_walker_bone(vol, seeds, t_bone=300.0)
    walker = [r for r in _records(caplog) if r.name == "wscg.volseg.walker"]
    assert walker, [r.name for r in caplog.records]
    assert walker[0].levelno == logging.INFO
    assert "2 labels" in walker[0].getMessage()


def test_level_set_on_the_wscg_logger_filters_records(caplog):
    vol = np.zeros((6, 6, 6), np.float32)
    vol[1:5, 1:5, 1:5] = 1.0
    with caplog.at_level(logging.WARNING, logger="wscg"):
        wscg.isosurface.marching_cubes(vol, 0.5)
    assert not [r for r in _records(caplog) if r.levelno < logging.WARNING]
    caplog.clear()
    with caplog.at_level(logging.DEBUG, logger="wscg"):
        wscg.isosurface.marching_cubes(vol, 0.5)
    debug = [r for r in _records(caplog) if r.name.startswith("wscg.isosurface")]
    assert debug and debug[0].levelno == logging.DEBUG
    assert "marching cubes" in debug[0].getMessage()


def test_unusable_nifti_orientation_is_a_warning(caplog, tmp_path):
    nib = pytest.importorskip("nibabel")
    data = os.path.join(os.path.dirname(nib.__file__), "tests", "data")
    # anatomical.nii's sform (x axis -2 mm) is kept as the affine: no warning. The same voxels
    # with a singular sform and no qform keep no orientation, which is worth a warning.
    with caplog.at_level(logging.WARNING, logger="wscg"):
        wscg.math.load_volume(os.path.join(data, "anatomical.nii"))
    assert not _records(caplog)
    img = nib.load(os.path.join(data, "anatomical.nii"))
    hdr = img.header.copy()
    hdr.set_qform(None, code=0)
    hdr["sform_code"] = 1
    for row in ("srow_x", "srow_y", "srow_z"):
        hdr[row] = 0.0
    bad = str(tmp_path / "singular.nii")
    nib.save(nib.Nifti1Image(np.asarray(img.dataobj), None, hdr), bad)
    assert nib.load(bad).header["sform_code"] == 1
    with caplog.at_level(logging.WARNING, logger="wscg"):
        got = wscg.math.load_volume(bad)
    warned = _records(caplog)
    assert len(warned) == 1 and warned[0].levelno == logging.WARNING
    assert warned[0].name.startswith("wscg.math")
    assert "singular.nii" in warned[0].getMessage() and "no orientation" in warned[0].getMessage()
    assert not got.has_affine


def test_records_of_concurrent_calls_from_two_python_threads_all_arrive(caplog):
    vol = np.zeros((8, 8, 8), np.float32)
    vol[2:6, 2:6, 2:6] = 1.0
    errors = []

    def work():
        try:
            for _ in range(5):
                wscg.isosurface.marching_cubes(vol, 0.5)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    with caplog.at_level(logging.DEBUG, logger="wscg"):
        threads = [threading.Thread(target=work) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert not errors
    got = [r for r in _records(caplog) if "marching cubes" in r.getMessage()]
    assert len(got) == 10
