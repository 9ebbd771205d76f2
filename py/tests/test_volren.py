"""Paper 03 (hybrid ROI visualisation) from Python: packages, lossless structure, the edge
voxel count against scipy's morphology (check 3), rendering consistency and bad input."""

import numpy as np
import pytest
from scipy.ndimage import binary_erosion, generate_binary_structure

from results_check import check_result
from wscg import volren as V


def test_addressing_example():
    # Check 1: the paper's example, voxel (x, y, z) = (171, 312, 237) given by its index
    # (k, j, i) in array axis order; the cell comes back in the same order.
    assert V.octree_address((237, 312, 171), 512) == ((14, 19, 10), [7, 1, 4, 5])
    with pytest.raises(ValueError):
        V.octree_address((0, 0, 600), 512)


def test_sphere_edge_voxels_match_scipy():
    # Check 3: binary sphere of radius 40 in 128^3, one TF opaque only above d = 150.
    n = 128
    z, y, x = np.mgrid[:n, :n, :n]
    mask = (x - 63.5) ** 2 + (y - 63.5) ** 2 + (z - 63.5) ** 2 <= 1600
    vol = np.where(mask, 200, 0).astype(np.uint8)
    tf = np.array([[150, 1, 1, 1, 0], [151, 1, 1, 1, 1]], dtype=float)
    s = V.HybridServer(vol, [tf])
    expected = np.sum(mask & ~binary_erosion(mask, generate_binary_structure(3, 1),
                                              border_value=0))
    assert s.leaf_count == expected
    # n_l: grey (R/l)^3 blocks, counted independently.
    edge = mask & ~binary_erosion(mask, generate_binary_structure(3, 1), border_value=0)
    zz, yy, xx = np.nonzero(edge)
    for t, count in enumerate(s.node_counts):
        shift = len(s.node_counts) - 1 - t
        blocks = {(a >> shift, b >> shift, c >> shift) for a, b, c in zip(xx, yy, zz)}
        assert count == len(blocks)


def test_server_client_round_trip_and_rendering():
    vol = V.make_phantom("head", (48, 96, 96), seed=1)
    assert vol.shape == (48, 96, 96) and vol.dtype == np.uint8
    tfs = V.phantom_tfs("head")
    s = V.HybridServer(vol, tfs)
    c = V.HybridClient(s.static_package())
    assert c.shape == (48, 96, 96)
    assert c.lowres.shape == (12, 24, 24)
    cam = V.orbit_camera(vol.shape)
    context = c.render(**cam, size=(40, 48), mode="context")
    assert context.shape == (40, 48, 4) and context.dtype == np.float32
    np.testing.assert_array_equal(c.render(**cam, size=(40, 48)), context)
    # (z0, z1, y0, y1, x0, x1), snapped outward to multiples of 16.
    c.set_roi(s.roi_package((5, 30, 30, 60, 20, 50)))
    assert c.roi == (0, 32, 16, 64, 16, 64)
    hybrid = c.render(**cam, size=(40, 48))
    assert np.abs(hybrid - context).max() > 0.01
    ref = V.render_reference(vol, tfs[0], **cam, size=(40, 48), roi=c.roi, roi_tf=tfs[1])
    assert ref.shape == (40, 48, 4)
    # ROI = whole volume: the hybrid image is the Gradient Octree image.
    c.set_roi(s.roi_package((0, 48, 0, 96, 0, 96)))
    np.testing.assert_array_equal(c.render(**cam, size=(24, 24)),
                                  c.render(**cam, size=(24, 24), mode="octree"))
    r = s.size_report((0, 32, 16, 64, 16, 64), thin_client_view=cam, viewport=(64, 64))
    check_result(r, V.SizeReport)
    assert r.hybrid == r.hybrid_static + r.hybrid_roi
    assert r.hybrid < r.gradient_octree < r.raw == vol.size
    assert r.thin_client_frame > 0 and r.wavelets > 0
    assert s.size_report((0, 32, 16, 64, 16, 64)).thin_client_frame is None


def test_bad_input():
    vol = V.make_phantom("head", (32, 32, 32), seed=2)
    tfs = V.phantom_tfs("head")
    s = V.HybridServer(vol, tfs)
    pkg = s.static_package()
    c = V.HybridClient(pkg)
    corrupted = bytearray(pkg)
    corrupted[len(pkg) // 2] ^= 1
    bad = [
        lambda: V.HybridServer(np.zeros((0, 4, 4), np.uint8), tfs),
        lambda: V.HybridServer(np.zeros((4, 4), np.uint8), tfs),
        lambda: V.HybridServer(vol, []),
        lambda: V.HybridServer(vol, tfs, canonical=5),
        lambda: V.HybridServer(vol, tfs, steps_sent=0),
        lambda: V.HybridServer(vol, [np.array([[10, 1, 1, 1, 0], [5, 1, 1, 1, 1]])]),
        lambda: V.HybridServer(vol, [np.array([[10, 1, 1, 1, 0], [20, 1, 1, 1, 1.5]])]),
        lambda: V.HybridServer(vol, [np.array([[10, 1, 1, 1, 0]])]),
        lambda: V.HybridServer(vol, [np.zeros((3, 4))]),
        lambda: s.roi_package((40, 50, 0, 10, 0, 10)),
        lambda: s.roi_package((10, 5, 0, 10, 0, 10)),
        lambda: s.roi_package((0, 10, 0, 10)),
        lambda: V.HybridClient(pkg[:-3]),
        lambda: V.HybridClient(bytes(corrupted)),
        lambda: V.HybridClient(b""),
        lambda: c.set_roi(pkg),
        lambda: c.render((0, 0, 0), (0, 0, 0)),
        lambda: c.render((100, 0, 0), (0, 0, 0), size=(0, 10)),
        lambda: c.render((100, 0, 0), (0, 0, 0), mode="mip"),
        lambda: V.make_phantom("knee"),
    ]
    for fn in bad:
        with pytest.raises(ValueError):
            fn()


def test_block_haar_matches_pywavelets():
    """Our averaging Haar equals PyWavelets' orthonormal one up to the per-level scale:
    step j's mean and details times (2 sqrt 2)^j are pywt's level-j coefficients."""
    pywt = pytest.importorskip("pywt")
    rng = np.random.default_rng(0)
    blocks = rng.uniform(0, 255, (3, 16, 16, 16)).astype(np.float32)
    ours = V.haar_blocks(blocks).astype(np.float64)
    ref = pywt.wavedecn(blocks.astype(np.float64), "haar", mode="periodization", level=4,
                        axes=(1, 2, 3))
    s = 2 * np.sqrt(2)
    np.testing.assert_allclose(ours[:, 0] * s ** 4, ref[0][:, 0, 0, 0], rtol=1e-5)
    offset = 1
    for level, det in enumerate(ref[1:]):  # coarse (step 4) to fine (step 1)
        j = 4 - level
        n = 16 >> j
        got = ours[:, offset:offset + 7 * n ** 3].reshape(3, n, n, n, 7)  # [z, y, x, k]
        offset += 7 * n ** 3
        for k in range(1, 8):
            u, v, w = (k >> 2) & 1, (k >> 1) & 1, k & 1
            key = ("d" if w else "a") + ("d" if v else "a") + ("d" if u else "a")
            np.testing.assert_allclose(got[..., k - 1] * s ** j, det[key], rtol=1e-4,
                                       atol=1e-3)
    with pytest.raises(ValueError):
        V.haar_blocks(np.zeros((2, 8, 8, 8)))
