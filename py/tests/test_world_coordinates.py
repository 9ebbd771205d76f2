"""One anisotropic volume through math, volseg, isosurface and volren: every module places the
voxel ``[k, j, i]`` of a volume with ``spacing = (dz, dy, dx)`` at the world point
``(x, y, z) = (i dx, j dy, k dz)`` (py/API.md). A module that took the spacing in another axis
order, or put its voxel centres elsewhere, moves the blob below and fails here."""

import struct

import numpy as np
import pytest

from wscg import isosurface, volren, volseg
from wscg import math as wm

SPACING = (2.0, 0.5, 1.0)          # (dz, dy, dx): three different values, none 1 apart
SHAPE = (16, 48, 24)               # (nz, ny, nx): 32 x 24 x 24 world units
INDEX = (7, 30, 10)                # the blob's voxel [k, j, i], away from every centre
SIGMA = 3.0                        # the blob's width, world units


def _world(index, spacing=SPACING):
    """py/API.md's formula: voxel [k, j, i] -> (x, y, z) = (i dx, j dy, k dz)."""
    (k, j, i), (dz, dy, dx) = index, spacing
    return np.array([i * dx, j * dy, k * dz])


POINT = _world(INDEX)              # (10.0, 15.0, 14.0)


def _blob(shape=SHAPE, spacing=SPACING, index=INDEX, sigma=SIGMA):
    """A Gaussian blob round in world units (an ellipsoid in voxels), peak 1 at ``index``."""
    k, j, i = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    x, y, z = _world((k, j, i), spacing)
    px, py, pz = _world(index, spacing)
    r2 = (x - px) ** 2 + (y - py) ** 2 + (z - pz) ** 2
    return np.exp(-r2 / (2 * sigma ** 2)).astype(np.float32)


def test_the_blob_and_the_formula():
    vol = _blob()
    assert np.unravel_index(np.argmax(vol), vol.shape) == INDEX
    np.testing.assert_array_equal(POINT, (10.0, 15.0, 14.0))


def _mesh_centroid(v, f):
    """Area-weighted centroid of a closed triangle mesh's surface."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return ((a + b + c) / 3 * area[:, None]).sum(0) / area.sum()


def test_isosurface_vertices_are_world_points():
    vol = _blob()
    v, f, n, info = isosurface.marching_cubes(vol, 0.5, spacing=SPACING, normals="central")
    # A sphere of radius sigma sqrt(2 ln 2) around the blob's world point.
    np.testing.assert_allclose(_mesh_centroid(v.astype(np.float64), f), POINT, atol=0.05)
    r = np.linalg.norm(v - POINT, axis=1)
    assert abs(np.median(r) - SIGMA * np.sqrt(2 * np.log(2))) < 0.1
    # Normals point along the gradient, towards the centre (increasing f).
    inward = np.sum(n * (POINT - v), axis=1)
    assert np.all(inward > 0)
    # The grid edges are (k, j, i, axis), array axis order: the low end of each edge is a
    # voxel whose world point lies within one spacing of the vertex along that axis.
    e = info.edges
    assert e.shape == (len(v), 4)
    low = np.stack([_world(row[:3]) for row in e])
    axis_xyz = 2 - e[:, 3]              # array axis 0 (z) is world axis 2
    step = np.array(SPACING)[e[:, 3]]
    d = v - low
    np.testing.assert_allclose(d[np.arange(len(v)), axis_xyz] / step, np.clip(
        d[np.arange(len(v)), axis_xyz] / step, 0, 1), atol=1e-5)
    off = np.ones_like(d, dtype=bool)
    off[np.arange(len(v)), axis_xyz] = False
    np.testing.assert_allclose(d[off], 0.0, atol=1e-4)
    # The origin (oz, oy, ox) shifts the vertices by (ox, oy, oz).
    v2, _, _, _ = isosurface.marching_cubes(vol, 0.5, spacing=SPACING, normals=None,
                                            origin=(-3.0, 5.0, 100.0))
    np.testing.assert_allclose(v2, v + np.array([100.0, 5.0, -3.0], np.float32), atol=1e-4)


def _nifti_header(path):
    """dim, pixdim and the sform rows of a NIfTI-1 file, read with struct (no library)."""
    with open(path, "rb") as fh:
        h = fh.read(348)
    assert struct.unpack("<i", h[:4])[0] == 348
    dim = struct.unpack("<8h", h[40:56])
    pixdim = struct.unpack("<8f", h[76:108])
    srow = np.array([struct.unpack("<4f", h[o:o + 16]) for o in (280, 296, 312)])
    return dim, pixdim, srow


def test_math_writes_the_formula_as_the_nifti_affine(tmp_path):
    vol = _blob()
    path = tmp_path / "blob.nii"
    wm.save_volume(path, vol, spacing=SPACING)
    dim, pixdim, srow = _nifti_header(path)
    # NIfTI's (i, j, k) is x fastest: numpy's [k, j, i].
    assert dim[:4] == (3, SHAPE[2], SHAPE[1], SHAPE[0])
    assert pixdim[1:4] == (1.0, 0.5, 2.0)
    k, j, i = INDEX
    np.testing.assert_allclose(srow @ np.array([i, j, k, 1.0]), POINT)
    back, spacing = wm.load_volume(path)
    assert spacing == SPACING
    np.testing.assert_array_equal(back, vol)


def test_math_nifti_affine_read_by_nibabel(tmp_path):
    nib = pytest.importorskip("nibabel")
    vol = _blob()
    path = tmp_path / "blob.nii.gz"
    wm.save_volume(path, vol, spacing=SPACING)
    img = nib.load(str(path))
    data = np.asarray(img.dataobj)
    k, j, i = INDEX
    assert data.shape == SHAPE[::-1]
    assert np.unravel_index(np.argmax(data), data.shape) == (i, j, k)
    np.testing.assert_allclose(img.affine @ np.array([i, j, k, 1.0]), [*POINT, 1.0])
    np.testing.assert_allclose(nib.affines.apply_affine(img.affine, np.argwhere(data == data.max())),
                               [POINT])


def test_math_to_isosurface_round_trip(tmp_path):
    # What math reads back feeds isosurface as it is: the same world point.
    path = tmp_path / "blob.nii"
    wm.save_volume(path, _blob(), spacing=SPACING)
    vol, spacing = wm.load_volume(path)
    v, f, _, _ = isosurface.marching_cubes(vol, 0.5, spacing=spacing, normals=None)
    np.testing.assert_allclose(_mesh_centroid(v.astype(np.float64), f), POINT, atol=0.05)


def test_math_mesh_files_keep_world_points(tmp_path):
    v, f, _, _ = isosurface.marching_cubes(_blob(), 0.5, spacing=SPACING, normals=None)
    for name in ("blob.ply", "blob.obj"):
        wm.save_mesh(tmp_path / name, v, f)
        m = wm.load_mesh(tmp_path / name)
        np.testing.assert_allclose(_mesh_centroid(m.vertices, m.faces), POINT, atol=0.05)


def test_volseg_smoothing_follows_the_spacing_axes():
    # The anisotropy-aware smoothing has sigma 0.6 min(spacing) in world units on every
    # axis: 0.6 voxel along y (dy = 0.5), 0.3 along x (dx = 1), 0.15 along z (dz = 2, below
    # the 3-tap kernel's reach, left alone). A delta at the blob's voxel spreads along y and
    # x only.
    delta = np.zeros(SHAPE, np.float32)
    delta[INDEX] = 1000.0
    sm = volseg.smooth(delta, 1, spacing=SPACING)
    k, j, i = INDEX
    assert sm[k - 1, j, i] == sm[k + 1, j, i] == 0.0
    assert sm[k, j - 1, i] > 0 and sm[k, j + 1, i] > 0
    assert sm[k, j, i - 1] > 0 and sm[k, j, i + 1] > 0
    assert sm[k, j - 1, i] > sm[k, j, i - 1]  # wider in voxels along the finer axis
    np.testing.assert_allclose(sm.sum(), 1000.0, rtol=1e-5)
    # Its bone mask and random walks see the same voxels.
    mask = volseg.bone_mask(delta, 1.0, n_smooth_passes=1, spacing=SPACING)
    np.testing.assert_array_equal(mask, sm >= 1.0)


def _alpha_centroid(img):
    """(row, column) of the alpha-weighted centre of an RGBA image."""
    a = img[..., 3].astype(np.float64)
    r, c = np.indices(a.shape)
    return np.array([(a * r).sum(), (a * c).sum()]) / a.sum()


TF = np.column_stack([np.ones((64, 3)), np.where(np.linspace(0, 1, 64) > 0.5, 0.6, 0.0)])


@pytest.mark.parametrize("prepared", [False, True])
def test_volren_centres_the_world_point(prepared):
    # An orthographic view down the z axis centred on the blob's world point: x to the
    # right, y down, 0.25 units of length per pixel.
    vol = _blob()
    if prepared:
        src, kw = volren.PreparedVolume(vol, spacing=SPACING, value_range=(0, 1)), {}
        assert src.spacing == SPACING
    else:
        src, kw = vol, {"spacing": SPACING, "value_range": (0, 1)}
    cam = dict(view_dir=(0, 0, 1), up=(0, -1, 0), size=(64, 80), pixel_size=0.25,
               method="raycast", slice_distance=0.25, **kw)
    img = volren.render(src, TF, center=tuple(POINT), **cam)
    assert img.shape == (64, 80, 4)
    np.testing.assert_allclose(_alpha_centroid(img), (31.5, 39.5), atol=0.05)
    # Moving the centre by (+2, -1) units of length moves the blob by (-8, +4) pixels
    # (columns along x, rows along y).
    moved = volren.render(src, TF, center=tuple(POINT + [2.0, -1.0, 0.0]), **cam)
    np.testing.assert_allclose(_alpha_centroid(moved), (31.5 + 4, 39.5 - 8), atol=0.05)


def test_volren_default_camera_frames_the_volume():
    # Without a pixel size the camera looks at the volume's centre, (n - 1) d / 2 per axis.
    vol = np.ones(SHAPE, np.float32)
    centre = _world([(n - 1) / 2 for n in SHAPE])
    fit = volren.render(vol, TF, spacing=SPACING, view_dir=(0, 0, 1), up=(0, -1, 0),
                        size=(60, 60), method="raycast", slice_distance=0.5, value_range=(0, 1))
    at = volren.render(vol, TF, spacing=SPACING, view_dir=(0, 0, 1), up=(0, -1, 0),
                       size=(60, 60), method="raycast", slice_distance=0.5, value_range=(0, 1),
                       center=tuple(centre))
    np.testing.assert_allclose(fit, at, atol=1e-6)
    # The fitted image holds the whole 24 x 24 box with a small border.
    rows = np.flatnonzero(fit[:, 30, 3] > 0.5)
    assert 0 < rows[0] < 5 and 55 < rows[-1] < 59


def test_volren_lengths_are_in_the_units_of_the_spacing():
    # A uniform slab 40 voxels of 0.5 deep is 20 units thick: with an opacity of 0.05 per
    # unit of length, 1 - 0.95^20 of the light is absorbed, whatever the slice distance.
    slab = np.ones((40, 32, 32), np.float32)
    tf = np.array([[1, 1, 1, 0.05], [1, 1, 1, 0.05]], np.float32)
    for ds in (0.25, 0.5):
        img = volren.render(slab, tf, spacing=(0.5, 0.5, 0.5), view_dir=(0, 0, 1),
                            up=(0, -1, 0), size=(16, 16), method="ics", kernel="delta",
                            slice_distance=ds)
        assert img[8, 8, 3] == pytest.approx(1 - 0.95 ** 20, abs=1e-4)
    # The light buffer's depths are lengths too: the slice nearest to 7.1 units down.
    buf, z = volren.light_buffer(slab, tf, 7.1, spacing=(0.5, 0.5, 0.5), view_dir=(0, 0, 1),
                                 up=(0, -1, 0), size=(16, 16), method="ics", kernel="delta",
                                 slice_distance=0.5)
    assert z == pytest.approx(7.25)
    assert buf[8, 8] == pytest.approx(0.95 ** 7.0, abs=1e-4)


def test_volren_paper03_cameras_use_the_same_formula():
    # Paper 03's volumes have unit spacing: voxel [k, j, i] is at (i, j, k). A bright ball
    # round that voxel, seen from above, sits at the image centre.
    shape, index = (32, 40, 48), (12, 25, 17)
    vol = (_blob(shape, (1.0, 1.0, 1.0), index, 2.0) * 255).astype(np.uint8)
    tf = np.array([[0, 1, 1, 1, 0], [100, 1, 1, 1, 0], [101, 1, 1, 1, 1], [255, 1, 1, 1, 1]],
                  float)
    p = _world(index, (1.0, 1.0, 1.0))
    for eye in (p + [0, 0, 30], p + [30, 0, 0], p - [0, 30, 0]):
        up = (0, 1, 0) if eye[2] != p[2] else (0, 0, 1)
        img = volren.render_reference(vol, tf, eye=tuple(eye), target=tuple(p), up=up,
                                      fov_deg=20.0, size=(65, 65))
        np.testing.assert_allclose(_alpha_centroid(img), (32.0, 32.0), atol=0.3)
    # The orbit camera looks at the volume's centre ((n - 1) / 2 per axis).
    cam = volren.orbit_camera(shape)
    np.testing.assert_allclose(cam["target"], _world([(n - 1) / 2 for n in shape],
                                                     (1.0, 1.0, 1.0)))
