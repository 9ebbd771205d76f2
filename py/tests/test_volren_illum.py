"""Paper 15 (convolution-based volume illumination) from Python: the exact Beer-Lambert slab
(check 1), delta kernel = shadow rays (check 3), the pre-integration table (check 4), the
VTI reader against an independent decoder, the Table-1 shape on the frog (check 5), the
study, the light buffer, dtype normalisation, determinism and bad input."""

import base64
import importlib.util
import re
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from results_check import check_result
from wscg import volren as V


# --------------------------------------------------------------------------------------------
# Helpers


def _pyvista_example(name: str) -> Path:
    """A data file shipped inside the pyvista wheel (pyvista is installed without its
    dependencies, so it is located, not imported)."""
    spec = importlib.util.find_spec("pyvista")
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("pyvista is not installed")
    p = Path(spec.submodule_search_locations[0]) / "examples" / name
    if not p.exists():
        pytest.skip(f"{p} is missing")
    return p


_VTK_TYPES = {"UInt8": "<u1", "Int8": "<i1", "UInt16": "<u2", "Int16": "<i2", "UInt32": "<u4",
              "Int32": "<i4", "UInt64": "<u8", "Int64": "<i8", "Float32": "<f4",
              "Float64": "<f8"}


def _decode_vti(path: Path):
    """Independent decoder of the two pyvista files: UInt32 header, zlib, base64 inline
    ("binary") or appended; header ``[nblocks, blocksize, lastsize, sizes...]`` and payload
    base64-encoded separately. Returns ``(array [z, y, x], spacing)``."""
    raw = path.read_bytes()
    app = raw.find(b"<AppendedData")
    xml = raw[: len(raw) if app < 0 else raw.index(b">", app) + 1].decode("ascii")
    assert 'header_type="UInt32"' in xml and 'compressor="vtkZLibDataCompressor"' in xml
    ext = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', xml).group(1).split()]
    spacing = tuple(float(v) for v in re.search(r'Spacing="([^"]+)"', xml).group(1).split())
    points = [ext[2 * a + 1] - ext[2 * a] + 1 for a in range(3)]
    pd = re.search(r"<PointData[^>]*>(.*?)</PointData>", xml, re.S)
    if pd and "<DataArray" in pd.group(1):
        dims, section = points, pd
    else:
        dims = [p - 1 for p in points]
        section = re.search(r"<CellData[^>]*>(.*?)</CellData>", xml, re.S)
    tag = re.search(r"<DataArray([^>]*)>", section.group(1))
    attrs = dict(re.findall(r'(\w+)="([^"]*)"', tag.group(1)))
    if attrs["format"] == "binary":
        body = section.group(1)[tag.end():]
        text = body[: body.index("</DataArray>")]
    else:
        assert attrs["format"] == "appended" and 'encoding="base64"' in xml
        start = raw.index(b"_", raw.index(b">", app)) + 1 + int(attrs["offset"])
        text = raw[start: raw.index(b"</AppendedData>")].decode("ascii")
    text = "".join(text.split())
    nblocks = struct.unpack("<I", base64.b64decode(text[:8])[:4])[0]
    head_bytes = 4 * (3 + nblocks)
    head_chars = -(-head_bytes // 3) * 4
    header = struct.unpack(f"<{3 + nblocks}I", base64.b64decode(text[:head_chars]))
    _, block, last, sizes = header[0], header[1], header[2], header[3:]
    payload = base64.b64decode(text[head_chars:])
    out, pos = [], 0
    for i, cs in enumerate(sizes):
        chunk = zlib.decompress(payload[pos: pos + cs])
        assert len(chunk) == (last if i == nblocks - 1 and last else block)
        out.append(chunk)
        pos += cs
    values = np.frombuffer(b"".join(out), dtype=_VTK_TYPES[attrs["type"]])
    return values.reshape(dims[2], dims[1], dims[0]), spacing


def _constant_tf(rgb, a, n=2):
    return np.tile(np.array([*rgb, a], dtype=np.float32), (n, 1))


def _orbit_dir(azimuth, elevation):
    a, e = np.radians(azimuth), np.radians(elevation)
    return (-np.cos(e) * np.cos(a), -np.cos(e) * np.sin(a), -np.sin(e))


def _laplacian_energy(a, b):
    d = (a[..., :3] - b[..., :3]).astype(np.float64)
    lap = (4 * d[1:-1, 1:-1] - d[:-2, 1:-1] - d[2:, 1:-1] - d[1:-1, :-2] - d[1:-1, 2:])
    return float(np.mean(lap ** 2))


# --------------------------------------------------------------------------------------------
# Check 1: the discrete Beer-Lambert slab


SLAB = np.ones((40, 64, 64), dtype=np.float32)  # [z, y, x]: 64 x 64 x 40 voxels
SLAB_CAM = dict(view_dir=(0, 0, 1), up=(0, -1, 0), size=(64, 64), pixel_size=1.0,
                kernel="delta")


@pytest.mark.parametrize("ds,want", [(0.25, 0.494895), (0.5, 0.498048), (1.0, 0.504351)])
def test_discrete_beer_lambert_slab(ds, want):
    tf = _constant_tf((1, 1, 1), 0.05)
    img = V.render(SLAB, tf, method="ics", slice_distance=ds, **SLAB_CAM)
    assert img.shape == (64, 64, 4) and img.dtype == np.float32
    alpha = 1 - 0.95 ** ds
    formula = (1 - (1 - alpha) ** (2 * 40 / ds)) / (2 - alpha)
    assert abs(formula - want) < 1e-6
    assert abs(img[32, 32, 0] - want) <= 1e-4
    # Grey light and grey tissue: every colour channel alike; the slab is uniform in x, y.
    np.testing.assert_allclose(img[32, 32, :3], img[32, 32, 0], atol=1e-7)
    np.testing.assert_allclose(img[16:48, 16:48, 0], img[32, 32, 0], atol=1e-6)
    # Alpha is the slab's opacity 1 - 0.95^40 whatever the slice distance.
    assert abs(img[32, 32, 3] - (1 - 0.95 ** 40)) <= 1e-4


def test_slab_light_buffer():
    """The light reaching slice k of a uniform slab under a delta kernel is (1 - alpha)^k;
    around the volume (pixel size 1, image wider than the volume) it is 1 when the value 0
    (the outside of the volume) is transparent, and attenuated when it is not."""
    tf = np.array([[1, 1, 1, 0], [1, 1, 1, 0.05]], np.float32)
    ds = 0.5
    for depth in (0.0, 7.3, 20.1):
        buf, z = V.light_buffer(SLAB, tf, depth, method="ics", slice_distance=ds,
                                **{**SLAB_CAM, "size": (72, 80)})
        assert buf.shape == (72, 80) and buf.dtype == np.float32
        k = max(round(depth / ds - 0.5), 0)
        assert z == pytest.approx((k + 0.5) * ds)
        assert buf[36, 40] == pytest.approx(0.95 ** (ds * k), abs=1e-5)
        assert np.all(buf[:, :7] == 1) and np.all(buf[:4, :] == 1)
        assert buf.min() >= 0 and buf.max() <= 1
    # The outside of the box is the value 0 throughout the volume's depth range: classified
    # by an opaque tf[0], it casts shadows too.
    fog, _ = V.light_buffer(SLAB, _constant_tf((1, 1, 1), 0.05), 20.1, method="ics",
                            slice_distance=ds, **{**SLAB_CAM, "size": (72, 80)})
    assert fog[36, 2] == pytest.approx(0.95 ** (ds * 40), abs=1e-5)


def test_closed_border_keeps_outside_light_out():
    """An opaque slab across the whole box 2 voxels thick, a headlight and a Gaussian kernel:
    with the open border the light beside the box leaks in under the slab's edges (half of
    it at the edge), with the closed border nothing arrives behind the slab; the delta kernel
    sees no border."""
    vol = np.zeros((40, 32, 48), np.float32)
    vol[5:7] = 1.0
    tf = np.array([[1, 1, 1, 0], [1, 1, 1, 0], [1, 1, 1, 1], [1, 1, 1, 1]], np.float32)
    cam = dict(size=(32, 48), pixel_size=1.0, value_range=(0.0, 1.0), method="ics",
               slice_distance=0.5, interp="nearest")
    open_, _ = V.light_buffer(vol, tf, 30.0, **cam)
    closed, _ = V.light_buffer(vol, tf, 30.0, border="closed", **cam)
    assert closed.max() < 1e-6
    assert open_[16, 0] > 0.3 and open_[0, 24] > 0.3 and open_[16, 24] < 1e-3
    delta = dict(cam, kernel="delta")
    assert np.array_equal(V.light_buffer(vol, tf, 30.0, **delta)[0],
                          V.light_buffer(vol, tf, 30.0, border="closed", **delta)[0])


# --------------------------------------------------------------------------------------------
# Check 3: delta kernel = shadow rays


def test_delta_kernel_equals_shadow_rays():
    vol, tf = V.make_marschner_lobb(41), V.marschner_lobb_tf()
    assert vol.shape == (41, 41, 41) and vol.dtype == np.float32 and tf.shape == (256, 4)
    cam = dict(view_dir=(0.3, -0.5, 1.0), up=(0, 1, 0), size=(64, 64), kernel="delta",
               value_range=(0, 1))
    for ds in (0.5, 1.0):
        ics = V.render(vol, tf, method="ics", slice_distance=ds, **cam)
        rays = V.render(vol, tf, method="shadow-rays", slice_distance=ds, **cam)
        ea = V.render(vol, tf, method="raycast", slice_distance=ds, **cam)
        assert V.mean_abs_diff(ics, rays) <= 1e-4
        # Shadows matter in this scene: emission-absorption alone differs.
        assert V.mean_abs_diff(ics, ea) > 1e-2
        # A blurring kernel is no longer the shadow-ray image.
        soft = V.render(vol, tf, method="ics", slice_distance=ds,
                        **{**cam, "kernel": "gaussian", "spread": 2.0})
        assert V.mean_abs_diff(soft, rays) > 1e-3


def test_marschner_lobb_values():
    """The analytic function on the axis r = 0 (rho = 1): (1 - sin(pi z / 2) + 0.5) / 2.5,
    that is 1, 0.6 and 0.2 at z = -1, 0, 1."""
    v = V.make_marschner_lobb(41)
    assert v[0, 20, 20] == pytest.approx(1.0, abs=1e-6)   # z = -1, r = 0
    assert v[20, 20, 20] == pytest.approx(0.6, abs=1e-6)  # z = 0, r = 0
    assert v[40, 20, 20] == pytest.approx(0.2, abs=1e-6)  # z = 1, r = 0
    # Symmetric under x <-> y (r only).
    np.testing.assert_array_equal(v, v.transpose(0, 2, 1))


# --------------------------------------------------------------------------------------------
# Check 4: pre-integration


def test_preintegration_table():
    tf = V.marschner_lobb_tf()
    n = tf.shape[0]
    tau = -np.log(1 - np.minimum(tf[:, 3].astype(np.float64), 1 - 1e-6))
    for ds in (0.5, 2.0):
        t = V.preintegration_table(tf, ds)
        assert t.shape == (n, n, 4) and t.dtype == np.float32
        np.testing.assert_allclose(np.diag(t[..., 3]), 1 - np.exp(-tau * ds), atol=2e-6)
        np.testing.assert_allclose(t[..., 3], t[..., 3].T, atol=1e-6)
        assert t.min() >= 0 and t[..., 3].max() <= 1
    # A transfer function whose extinction is linear in s: tau(s) = k s.
    k = 2.0
    s = np.linspace(0, 1, 64)
    colour = np.stack([s, 1 - s, np.full_like(s, 0.5)], axis=1)
    lin = np.column_stack([colour, 1 - np.exp(-k * s)]).astype(np.float32)
    for ds in (0.5, 1.5):
        t = V.preintegration_table(lin, ds)
        want = 1 - np.exp(-k * ds * (s[:, None] + s[None, :]) / 2)
        np.testing.assert_allclose(t[..., 3], want, atol=1e-4)
        # The colour is not symmetric: red grows along s, so a segment ending in red
        # (back) shows less of it than one starting there.
        f, b = 3, 60
        assert t[b, f, 0] > t[f, b, 0] + 1e-3


# --------------------------------------------------------------------------------------------
# The VTI reader


@pytest.fixture(scope="module")
def frog():
    """The frog tissue labels ``[z, y, x]`` and spacing, read once."""
    return V.load_vti(_pyvista_example("frog_tissues.vti"))


def test_load_vti_frog_matches_independent_decoder(frog):
    path = _pyvista_example("frog_tissues.vti")
    labels, spacing = frog
    assert labels.shape == (136, 470, 500) and labels.dtype == np.uint8
    # (dz, dy, dx): the file's Spacing="1 1 1.5" lists x first.
    assert spacing == (1.5, 1.0, 1.0)
    assert labels.min() == 0 and labels.max() == 29
    ref, ref_spacing = _decode_vti(path)
    assert ref_spacing[::-1] == spacing
    np.testing.assert_array_equal(labels, ref)
    assert set(np.unique(labels)) <= set(range(30))
    # str paths work too.
    np.testing.assert_array_equal(V.load_vti(str(path))[0][::17, ::13, ::11],
                                  labels[::17, ::13, ::11])


def test_load_vti_appended_int64_cells():
    path = _pyvista_example("channels.vti")
    facies, spacing = V.load_vti(path)
    ref, ref_spacing = _decode_vti(path)
    assert facies.dtype == np.int64 and facies.shape == ref.shape == (100, 250, 250)
    assert spacing == ref_spacing == (1.0, 1.0, 1.0)
    np.testing.assert_array_equal(facies, ref)
    assert facies.min() == 0 and facies.max() == 4


def test_load_vti_bad_files(tmp_path):
    raw = _pyvista_example("frog_tissues.vti").read_bytes()
    appended = _pyvista_example("channels.vti").read_bytes()
    cut_points = [len(raw) // 2, len(raw) - 100, 700, 400, 300, 50]
    for i, cut in enumerate(cut_points):
        p = tmp_path / f"frog_cut{i}.vti"
        p.write_bytes(raw[:cut])
        with pytest.raises(ValueError):
            V.load_vti(p)
    for i, cut in enumerate([len(appended) // 2, len(appended) - 50, 1000]):
        p = tmp_path / f"channels_cut{i}.vti"
        p.write_bytes(appended[:cut])
        with pytest.raises(ValueError):
            V.load_vti(p)
    # A corrupted compressed block and a header announcing more blocks than there are.
    start = raw.index(b'format="binary"')
    start = raw.index(b">", start) + 1
    text = raw[start:].lstrip()
    offset = len(raw) - len(text)
    corrupt = bytearray(raw)
    corrupt[offset + 20000: offset + 20008] = b"AAAAAAAA"
    (tmp_path / "corrupt.vti").write_bytes(bytes(corrupt))
    with pytest.raises(ValueError):
        V.load_vti(tmp_path / "corrupt.vti")
    lying = bytearray(raw)
    lying[offset: offset + 8] = base64.b64encode(struct.pack("<I", 5000) + b"\0\0")
    (tmp_path / "lying.vti").write_bytes(bytes(lying))
    with pytest.raises(ValueError):
        V.load_vti(tmp_path / "lying.vti")
    # Headers the parser indexes past (a padded first quantum; a UInt64 block count that
    # overflows): still a ValueError, not a Rust panic surfacing as PanicException.
    tiny = ('<?xml version="1.0"?>\n<VTKFile type="ImageData" version="0.1" '
            'byte_order="LittleEndian" header_type="{h}" compressor="vtkZLibDataCompressor">'
            '<ImageData WholeExtent="0 1 0 1 0 1" Origin="0 0 0" Spacing="1 1 1">'
            '<Piece Extent="0 1 0 1 0 1"><PointData><DataArray type="UInt8" Name="a" '
            'format="binary">{body}</DataArray></PointData></Piece></ImageData></VTKFile>')
    for h, body in [("UInt32", "AAAAAAAAAAAAAA=="),
                    ("UInt64", base64.b64encode(struct.pack("<QQQ", 2**64 - 1, 8, 8)).decode())]:
        (tmp_path / "hostile.vti").write_text(tiny.format(h=h, body=body))
        with pytest.raises(ValueError):
            V.load_vti(tmp_path / "hostile.vti")
    (tmp_path / "text.vti").write_text("not xml at all")
    with pytest.raises(ValueError):
        V.load_vti(tmp_path / "text.vti")
    with pytest.raises(OSError):
        V.load_vti(tmp_path / "missing.vti")
    with pytest.raises(OSError):
        V.load_vti(tmp_path)  # a directory
    with pytest.raises(ValueError):
        V.load_vti(12)


# --------------------------------------------------------------------------------------------
# Check 5: the shape of Table 1 on the frog


def test_table1_shape_on_frog(frog):
    labels, _ = frog
    dens = V.labels_to_density(labels[::2, ::2, ::2], spacing=(1.5, 1, 1), sigma=1.0)
    assert dens.shape == (68, 235, 250) and dens.dtype == np.float32
    assert dens.min() >= 0 and dens.max() <= 1
    # The steep skin transfer function (the paper's sharp-TF scenes): the body surface
    # aliases at coarse slice distances, so the errors are large enough to be resolved.
    tf = V.skin_tf()
    views = [dict(view_dir=(1, 0.6, -0.5), up=(0, 0, 1)),
             dict(view_dir=(-0.7, 1, -0.4), up=(0, 0, 1))]

    def images(method, ds, m):
        return [V.render(dens, tf, spacing=(1.5, 1, 1), size=(128, 128), method=method,
                         slice_distance=ds, n_subsamples=m, value_range=(0, 1), **v)
                for v in views]

    ref = images("ics", 0.2, 0)

    def mad(method, ds, m):
        return float(np.mean([V.mean_abs_diff(a, r)
                              for a, r in zip(images(method, ds, m), ref)]))

    m0 = [mad("ics", d, 0) for d in (0.4, 0.6, 0.8)]
    diag = {(d, m): mad("scs", d, m) for d, m in ((0.4, 1), (0.6, 2), (0.8, 3))}
    print(f"\nfrog Table 1: MAD(m=0) over 0.4, 0.6, 0.8 = {m0}; diagonal SCS {diag}; "
          f"MAD(0.8, m=3) / MAD(0.8, m=0) = {diag[(0.8, 3)] / m0[2]:.3f}")
    assert m0[0] < m0[1] < m0[2]
    assert diag[(0.8, 3)] <= 0.6 * m0[2]
    assert all(v <= 0.01 for v in diag.values())


# --------------------------------------------------------------------------------------------
# The study


def test_study_matches_independent_renders():
    # A 32-entry transfer function keeps the pre-integration tables (N x N) small.
    vol, tf = V.make_marschner_lobb(21), V.marschner_lobb_tf()[::8]
    kw = dict(n_views=2, size=24, azimuth=10.0, elevation=25.0, distances=(0.5, 1.0),
              max_subsamples=1, reference=0.25, fine=0.125, value_range=(0, 1))
    st = V.study(vol, tf, **kw)
    text = check_result(st, V.IlluminationStudy)
    assert "entries=list(len=8)" in text
    check_result(st.entries[0], V.StudyEntry)
    got = [(e.method, e.slice_distance, e.n_subsamples) for e in st.entries]
    assert got == [("ics", 0.5, 0), ("scs", 0.5, 1), ("pi-ics", 0.5, 0), ("pi-scs", 0.5, 1),
                   ("ics", 1.0, 0), ("scs", 1.0, 1), ("pi-ics", 1.0, 0), ("pi-scs", 1.0, 1)]
    # The orbit cameras, the reference and the scores, rebuilt from render().
    cams = [dict(view_dir=_orbit_dir(10.0 + 180.0 * k, 25.0), up=(0, 0, 1), size=(24, 24),
                 value_range=(0, 1)) for k in range(2)]
    ref = [V.render(vol, tf, method="ics", slice_distance=0.25, **c) for c in cams]
    fine = [V.render(vol, tf, method="ics", slice_distance=0.125, **c) for c in cams]
    fine_energy = np.mean([_laplacian_energy(f, r) for f, r in zip(fine, ref)])
    assert st.fine_energy == pytest.approx(fine_energy, rel=1e-4)
    for e in st.entries:
        imgs = [V.render(vol, tf, method=e.method, slice_distance=e.slice_distance,
                         n_subsamples=e.n_subsamples, **c) for c in cams]
        assert e.mad == pytest.approx(np.mean([V.mean_abs_diff(a, r)
                                               for a, r in zip(imgs, ref)]), rel=1e-4)
        assert e.energy == pytest.approx(np.mean([_laplacian_energy(a, r)
                                                  for a, r in zip(imgs, ref)]), rel=1e-4)
        assert e.alias_free == (e.mad <= 0.005 and e.energy <= 2 * st.fine_energy)
        assert e.seconds > 0
    assert st.reference_seconds > 0
    # A looser criterion only adds alias-free entries.
    loose = V.study(vol, tf, **kw, max_mad=1.0, max_energy_ratio=1e9)
    assert all(e.alias_free for e in loose.entries)


# --------------------------------------------------------------------------------------------
# Normalisation, determinism, inputs untouched


def test_dtype_normalisation_paths_agree():
    rng = np.random.default_rng(3)
    u8 = rng.integers(0, 256, (12, 14, 16), dtype=np.uint8)
    u8[0, 0, 0], u8[-1, -1, -1] = 0, 255
    tf = np.column_stack([np.linspace(0, 1, 64)] * 3 + [np.linspace(0, 0.4, 64)])
    kw = dict(view_dir=(0.2, 0.3, 1), size=(18, 20), method="scs", n_subsamples=1,
              slice_distance=0.7)
    base = V.render(u8, tf, **kw)
    assert base.shape == (18, 20, 4)
    same = [
        V.render(u8.astype(np.uint16) * 257, tf, **kw),             # v / 65535
        V.render(u8.astype(np.float32), tf, **kw),                  # min/max = 0/255
        V.render(u8.astype(np.float32) / 255, tf, value_range=(0, 1), **kw),
        V.render(u8.astype(np.float32) * 2 - 7, tf, value_range=(-7, 503), **kw),
        V.render(u8.astype(np.uint16), tf, value_range=(0, 255), **kw),
        V.render(np.asfortranarray(u8), tf, **kw),                 # non-contiguous input
        V.render(u8.astype(">u2") * 257, tf, **kw),                # big-endian
    ]
    for img in same:
        np.testing.assert_allclose(img, base, atol=2e-6)
    # The colour ramp matters: remapping the range changes the image.
    other = V.render(u8.astype(np.float32), tf, value_range=(0, 510), **kw)
    assert np.abs(other - base).max() > 1e-2
    # A constant float volume does not break the min/max mapping.
    flat = V.render(np.full((4, 5, 6), 3.0, np.float32), tf, **kw)
    assert np.all(np.isfinite(flat))


def test_deterministic_and_inputs_untouched():
    vol = V.make_marschner_lobb(25)
    tf = V.marschner_lobb_tf()
    vol_copy, tf_copy = vol.copy(), tf.copy()
    for method, m in (("scs", 2), ("pi-scs", 1), ("phong", 0), ("ics", 0)):
        kw = dict(view_dir=(0.4, -0.7, 1.0), size=(40, 32), method=method,
                  slice_distance=0.8, n_subsamples=m, light_dir=(0.3, 0.2, 1.0), ambient=0.1,
                  background=(0.2, 0.3, 0.4))
        a = V.render(vol, tf, **kw)
        b = V.render(vol, tf, **kw)
        np.testing.assert_array_equal(a, b)
        assert np.all(np.isfinite(a)) and a.min() >= 0
        if method != "phong":  # specular highlights may exceed 1
            assert a.max() <= 1 + 1e-6
    np.testing.assert_array_equal(vol, vol_copy)
    np.testing.assert_array_equal(tf, tf_copy)
    labels = (V.make_marschner_lobb(16) * 5).astype(np.uint8)
    labels_copy = labels.copy()
    V.labels_to_density(labels)
    np.testing.assert_array_equal(labels, labels_copy)


def test_prepared_volume_renders_like_the_array():
    vol, tf = V.make_marschner_lobb(25), V.marschner_lobb_tf()
    vol_copy = vol.copy()
    pv = V.PreparedVolume(vol, spacing=(1.5, 1.0, 1.0))
    assert pv.shape == vol.shape and pv.spacing == (1.5, 1.0, 1.0)
    assert "PreparedVolume" in repr(pv)
    for method, m in (("phong", 0), ("raycast", 0), ("ics", 0), ("pi-scs", 1)):
        kw = dict(view_dir=(0.4, -0.7, 1.0), size=(40, 32), method=method,
                  slice_distance=0.8, n_subsamples=m, light_dir=(0.3, 0.2, 1.0))
        want = V.render(vol, tf, spacing=(1.5, 1.0, 1.0), **kw)
        for _ in range(2):  # the second render reuses the cells and bricks
            np.testing.assert_array_equal(V.render(pv, tf, **kw), want)
    buf, z = V.light_buffer(pv, tf, 5.0, size=(20, 20), method="ics", slice_distance=0.5)
    buf2, z2 = V.light_buffer(vol, tf, 5.0, spacing=(1.5, 1.0, 1.0), size=(20, 20),
                              method="ics", slice_distance=0.5)
    np.testing.assert_array_equal(buf, buf2)
    assert z == z2
    kw = dict(n_views=1, size=24, distances=(0.8,), max_subsamples=1)
    a = V.study(pv, tf, **kw).entries
    b = V.study(vol, tf, spacing=(1.5, 1.0, 1.0), **kw).entries
    assert [e.mad for e in a] == [e.mad for e in b]
    np.testing.assert_array_equal(vol, vol_copy)
    with pytest.raises(ValueError, match="PreparedVolume"):
        V.render(pv, tf, spacing=(1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="PreparedVolume"):
        V.render(pv, tf, value_range=(0.0, 1.0))
    with pytest.raises(ValueError, match="3-D"):
        V.PreparedVolume(np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="spacing"):
        V.PreparedVolume(vol, spacing=(1.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="non-finite"):
        V.PreparedVolume(np.full((3, 3, 3), np.nan, np.float32))


def test_methods_kernels_and_transparent_volume():
    vol, tf = V.make_marschner_lobb(21), V.marschner_lobb_tf()
    kw = dict(view_dir=(0.4, -0.7, 1.0), size=(24, 24), slice_distance=0.5,
              value_range=(0, 1))
    imgs = {k: V.render(vol, tf, method="ics", kernel=k, tan_half=6.0, **kw)
            for k in V.KERNELS}
    # Every kernel gives its own picture; a disk narrower than a pixel is the delta kernel.
    assert V.mean_abs_diff(imgs["gaussian"], imgs["delta"]) > 1e-4
    assert V.mean_abs_diff(imgs["disk"], imgs["delta"]) > 1e-4
    assert V.mean_abs_diff(imgs["disk"], imgs["gaussian"]) > 1e-4
    thin = V.render(vol, tf, method="ics", kernel="disk", tan_half=0.1, **kw)
    np.testing.assert_allclose(thin, imgs["delta"], atol=1e-5)
    # Pre-integration differs from post-classification at this distance.
    pi = V.render(vol, tf[::4], method="pi-ics", **kw)
    assert V.mean_abs_diff(pi, V.render(vol, tf[::4], method="ics", **kw)) > 1e-5
    # "scs" with no sub-samples is ICS.
    np.testing.assert_array_equal(V.render(vol, tf, method="scs", **kw), imgs["gaussian"])
    # More ambient light brightens.
    lit = V.render(vol, tf, method="ics", ambient=0.5, **kw)
    assert lit[..., :3].sum() > imgs["gaussian"][..., :3].sum()
    # An all-transparent volume: the background, alpha 0, unoccluded light.
    clear = _constant_tf((1, 0, 0), 0.0)
    for me in V.METHODS:
        img = V.render(vol, clear, method=me, background=(0.1, 0.2, 0.3), **kw)
        np.testing.assert_allclose(img[..., :3], np.broadcast_to([0.1, 0.2, 0.3], (24, 24, 3)),
                                   atol=1e-7)
        assert np.all(img[..., 3] == 0)
    buf, _ = V.light_buffer(vol, clear, 10.0, **kw)
    assert np.all(buf == 1)


# --------------------------------------------------------------------------------------------
# Bad input


def test_bad_input_raises_value_error():
    vol = np.zeros((6, 7, 8), np.uint8)
    tf = _constant_tf((1, 1, 1), 0.5)
    nan_vol = np.zeros((6, 7, 8), np.float32)
    nan_vol[1, 2, 3] = np.nan
    img = np.zeros((4, 4, 4), np.float32)
    r = V.render
    bad = [
        (lambda: r(vol.astype(np.float64), tf), "volume"),
        (lambda: r(vol.astype(np.int32), tf), "volume"),
        (lambda: r(vol.astype(bool), tf), "volume"),
        (lambda: r(vol[0], tf), "volume"),
        (lambda: r(np.zeros((0, 4, 4), np.uint8), tf), "dims"),
        (lambda: r(nan_vol, tf), "volume"),
        (lambda: r(vol, tf[:, :3]), "tf"),
        (lambda: r(vol, tf[:1]), "tf"),
        (lambda: r(vol, np.array([[1, 1, 1, np.nan], [1, 1, 1, 1]])), "tf"),
        (lambda: r(vol, np.array([[1, 1, 1, 1.5], [1, 1, 1, 1]])), "tf"),
        (lambda: r(vol, tf, spacing=(0, 1, 1)), "spacing"),
        (lambda: r(vol, tf, spacing=(np.nan, 1, 1)), "spacing"),
        (lambda: r(vol, tf, spacing=(1, 1)), "spacing"),
        (lambda: r(vol, tf, slice_distance=0), "slice_distance"),
        (lambda: r(vol, tf, slice_distance=-1), "slice_distance"),
        (lambda: r(vol, tf, slice_distance=np.nan), "slice_distance"),
        (lambda: r(vol, tf, method="raycast", slice_distance=0), "slice_distance"),
        (lambda: r(vol, tf, n_subsamples=65), "n_subsamples"),
        (lambda: r(vol, tf, n_subsamples=-1), "n_subsamples"),
        (lambda: r(vol, tf, n_subsamples=1.5), "n_subsamples"),
        (lambda: r(vol, tf, method="ics", n_subsamples=2), "scs"),
        (lambda: r(vol, tf, method="pi-ics", n_subsamples=2), "pi-scs"),
        (lambda: r(vol, tf, method="raycast", n_subsamples=2), "n_subsamples"),
        (lambda: r(vol, tf, size=(0, 10)), "size"),
        (lambda: r(vol, tf, size=(10, -1)), "size"),
        (lambda: r(vol, tf, size=(1 << 14, 1 << 14)), "size"),
        (lambda: r(vol, tf, size=10), "size"),
        (lambda: r(vol, tf, spread=-1), "spread"),
        # Renders that would not finish or would exhaust memory.
        (lambda: r(vol, tf, slice_distance=1e-7), "slice_distance"),
        (lambda: r(vol, tf, method="shadow-rays", slice_distance=1e-7), "slice_distance"),
        # Lengths are in the units of the spacing: an extreme spacing makes them unusable.
        (lambda: r(vol, tf, spacing=(1e-300, 1, 1)), "spread"),
        (lambda: r(vol, tf, spacing=(1e-300, 1, 1), kernel="delta"), "slice_distance"),
        (lambda: r(vol, tf, spread=1e30), "spread"),
        (lambda: r(vol, tf, kernel="disk", tan_half=1e9), "tan_half"),
        (lambda: V.study(vol, tf, spread=1e30), "spread"),
        (lambda: r(vol, tf, kernel="disk", tan_half=-0.5), "tan_half"),
        (lambda: r(vol, tf, light_dir=(0, 0, -1)), "light_dir"),
        (lambda: r(vol, tf, light_dir=(1, 0, 0)), "light_dir"),
        (lambda: r(vol, tf, light_dir=(0, 0, np.nan)), "light_dir"),
        (lambda: r(vol, tf, method="mip"), "method"),
        (lambda: r(vol, tf, kernel="box"), "kernel"),
        (lambda: r(vol, tf, interp="cubic"), "interp"),
        (lambda: r(vol, tf, light_attenuation="none"), "light_attenuation"),
        (lambda: r(vol, tf, border="walls"), "border"),
        (lambda: r(vol, tf, pixel_size=0), "pixel_size"),
        (lambda: r(vol, tf, pixel_size=-2), "pixel_size"),
        (lambda: r(vol, tf, view_dir=(0, 0, 0)), "view_dir"),
        (lambda: r(vol, tf, view_dir=(0, 1, 0)), "up"),
        (lambda: r(vol, tf, center=(0, np.inf, 0), pixel_size=1), "center"),
        (lambda: r(vol.astype(np.float32), tf, value_range=(1, 0)), "value_range"),
        (lambda: r(vol, tf, ambient=2), "ambient"),
        (lambda: r(vol, tf, background=(2, 0, 0)), "background"),
        (lambda: V.light_buffer(vol, tf, -1.0), "depth"),
        (lambda: V.light_buffer(vol, tf, np.nan), "depth"),
        (lambda: V.light_buffer(vol, tf, 1.0, method="raycast"), "method"),
        (lambda: V.preintegration_table(tf, 0), "ds"),
        (lambda: V.preintegration_table(tf, np.nan), "ds"),
        (lambda: V.preintegration_table(tf[:, :2], 1), "tf"),
        (lambda: V.make_marschner_lobb(1), "n"),
        (lambda: V.make_marschner_lobb(100000), "n"),
        (lambda: V.labels_to_density(vol.astype(np.float32)), "labels"),
        (lambda: V.labels_to_density(vol.astype(np.int16) - 1), "labels"),
        (lambda: V.labels_to_density(vol[0]), "labels"),
        (lambda: V.labels_to_density(vol, sigma=-1), "sigma"),
        (lambda: V.labels_to_density(vol, spacing=(1, 0, 1)), "spacing"),
        (lambda: V.mean_abs_diff(img, img[:3]), "shape"),
        (lambda: V.mean_abs_diff(img[..., :2], img[..., :2]), "C >= 3"),
        (lambda: V.mean_abs_diff(img[..., 0], img[..., 0]), "a"),
        (lambda: V.mean_abs_diff(img * np.nan, img), "a"),
        (lambda: V.study(vol, tf, n_views=0), "n_views"),
        (lambda: V.study(vol, tf, size=0), "size"),
        (lambda: V.study(vol, tf, distances=()), "distances"),
        (lambda: V.study(vol, tf, distances=(0.5, 0)), "distances"),
        (lambda: V.study(vol, tf, max_subsamples=65), "max_subsamples"),
        (lambda: V.study(vol, tf, reference=0), "reference"),
        (lambda: V.study(vol, tf, fine=-1), "fine"),
        (lambda: V.study(vol, tf, spread=-1), "spread"),
        (lambda: V.study(vol, tf, light_dir=(0, 0, -1)), "light_dir"),
        (lambda: V.study(vol, tf, max_mad=np.nan), "max_mad"),
    ]
    for fn, name in bad:
        with pytest.raises(ValueError, match=re.escape(name)):
            fn()


def test_native_functions_validate_directly():
    """The native layer checks its own input (a direct call cannot panic)."""
    from wscg._native import volren as N

    vol = np.zeros((4, 4, 4), np.uint8)
    tf = _constant_tf((1, 1, 1), 0.5)
    with pytest.raises(ValueError, match="volume"):
        N.illum_render(np.zeros((4, 4, 4)), tf, [1, 1, 1], None, {})
    with pytest.raises(ValueError, match="unknown option"):
        N.illum_render(vol, tf, [1, 1, 1], None, {"slice_distanse": 1.0})
    with pytest.raises(ValueError, match="n_subsamples"):
        N.illum_render(vol, tf, [1, 1, 1], None, {"n_subsamples": -3})
    with pytest.raises(ValueError, match="size"):
        N.illum_render(vol, tf, [1, 1, 1], None, {"size": (-4, 4)})
    with pytest.raises(ValueError, match="`tf`"):
        N.illum_render(vol, np.zeros((3, 3), np.float32), [1, 1, 1], None, {})
    img = N.illum_render(vol, tf, [1, 1, 1], None, {"size": (8, 6), "method": "ics"})
    assert img.shape == (8, 6, 4) and img.dtype == np.float32  # size is (height, width)
