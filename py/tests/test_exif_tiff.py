"""16-bit PNG and TIFF in and out (checked against tifffile, Pillow and imageio reading the
same files), EXIF exposure settings of photographs (files written by Pillow), and the HDR
functions and command taking their exposure times from EXIF."""

import os
import struct
import subprocess
import warnings

import cv2
import numpy as np
import pytest
import tifffile
from PIL import Image as PILImage
from PIL.TiffImagePlugin import IFDRational

import imageio.v3 as iio
import wscg.hdr as hdr
import wscg.math as wm


def _ramp(h, w, c, dtype):
    top = np.iinfo(dtype).max
    v = np.linspace(0, top, h * w * c).round().astype(dtype).reshape(h, w, c)
    return v[..., 0] if c == 1 else v


@pytest.mark.parametrize("ext", [".png", ".tif"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("channels", [1, 3, 4])
def test_integer_images_are_written_at_their_depth_and_read_back_exactly(
        tmp_path, ext, dtype, channels):
    a = _ramp(9, 13, channels, dtype)
    p = tmp_path / f"img{ext}"
    wm.save_image(p, a)
    # OpenCV reads every depth (BGR order); Pillow (and imageio's PNG plugin, which is
    # Pillow) reads 16-bit grey but not 16-bit colour at full depth.
    bgr = cv2.imread(str(p), cv2.IMREAD_UNCHANGED)
    refs = [bgr if channels == 1 else bgr[..., [2, 1, 0, 3][:channels]]]
    if dtype == np.uint8 or channels == 1:
        refs += [np.asarray(PILImage.open(p)), iio.imread(p)]
    assert refs[0].dtype == dtype
    for ref in refs:
        assert ref.shape == a.shape, ref.shape
        np.testing.assert_array_equal(ref.astype(np.int64), a)
    if ext == ".tif":
        np.testing.assert_array_equal(tifffile.imread(p), a)
    back = wm.load_image(p)
    scale = np.iinfo(dtype).max
    assert back.shape == a.shape
    np.testing.assert_array_equal(np.round(back * scale).astype(dtype), a)


def test_bit_depth_keyword_and_float_tiff(tmp_path):
    x = np.linspace(0, 1, 5 * 7 * 3).reshape(5, 7, 3)
    p = tmp_path / "f16.tif"
    wm.save_image(p, x, bit_depth=16)
    ref = tifffile.imread(p)
    assert ref.dtype == np.uint16
    np.testing.assert_array_equal(ref, np.round(x * 65535).astype(np.uint16))
    wm.save_image(tmp_path / "f8.tiff", x)
    assert tifffile.imread(tmp_path / "f8.tiff").dtype == np.uint8
    big = (x * 40).astype(np.float32)
    wm.save_image(tmp_path / "f32.tif", big, bit_depth=32)
    np.testing.assert_array_equal(tifffile.imread(tmp_path / "f32.tif"), big)
    np.testing.assert_array_equal(wm.load_image(tmp_path / "f32.tif"), big)
    # uint16 to an 8-bit format is scaled, not clipped.
    wm.save_image(tmp_path / "u16.jpg", _ramp(8, 8, 3, np.uint16))
    assert iio.imread(tmp_path / "u16.jpg").max() > 200
    with pytest.raises(OSError, match="la.tif"):
        wm.save_image(tmp_path / "la.tif", np.zeros((4, 4, 2)))


@pytest.mark.parametrize("compression", [None, "zlib"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_tifffile_written_tiffs_are_read(tmp_path, compression, dtype):
    a = _ramp(17, 11, 3, dtype)
    p = tmp_path / "t.tif"
    tifffile.imwrite(p, a, photometric="rgb", compression=compression)
    back = wm.load_image(p)
    np.testing.assert_array_equal(np.round(back * np.iinfo(dtype).max).astype(dtype), a)
    g = a[..., 1]
    tifffile.imwrite(p, g, photometric="minisblack", compression=compression)
    back = wm.load_image(p)
    assert back.shape == g.shape
    np.testing.assert_array_equal(np.round(back * np.iinfo(dtype).max).astype(dtype), g)


def test_scikit_image_multipage_tiff_reads_its_first_page():
    import skimage
    src = os.path.join(os.path.dirname(skimage.__file__), "data", "multipage.tif")
    ref = tifffile.imread(src, key=0)
    np.testing.assert_array_equal(np.round(wm.load_image(src) * 255).astype(np.uint8), ref)


def _tiff(w, h, strip=12, magic=42):
    """A little-endian 8-bit grey TIFF declaring w x h pixels in one strip of 12 bytes."""
    entries = [(256, 4, w), (257, 4, h), (258, 3, 8), (259, 3, 1), (262, 3, 1),
               (273, 4, 8 + 2 + 9 * 12 + 4), (277, 3, 1), (278, 4, h), (279, 4, strip)]
    out = b"II" + struct.pack("<HI", magic, 8) + struct.pack("<H", len(entries))
    for tag, kind, value in entries:
        out += struct.pack("<HHI", tag, kind, 1)
        out += struct.pack("<HH", value, 0) if kind == 3 else struct.pack("<I", value)
    return out + struct.pack("<I", 0) + bytes(range(0, 240, 20))


def test_bad_tiffs_are_errors_naming_the_file(tmp_path):
    good = tmp_path / "good.tif"
    good.write_bytes(_tiff(4, 3))
    assert wm.load_image(good).shape == (3, 4)
    np.testing.assert_array_equal(tifffile.imread(good), np.arange(0, 240, 20).reshape(3, 4))
    for name, data in [("cut.tif", _tiff(4, 3)[:40]), ("magic.tif", _tiff(4, 3, magic=41)),
                       ("empty.tif", b"")]:
        p = tmp_path / name
        p.write_bytes(data)
        with pytest.raises(OSError, match=name):
            wm.load_image(p)
    bomb = tmp_path / "bomb.tif"
    bomb.write_bytes(_tiff(20000, 20000))
    with pytest.raises((ValueError, MemoryError), match="bomb.tif.*limit"):
        wm.load_image(bomb)


# ------------------------------------------------------------------------------ EXIF


def _jpeg(path, t=None, f_number=None, iso=None, value=128):
    """An 8-bit JPEG with the given EXIF exposure settings (Pillow writes the Exif IFD)."""
    rng = np.random.default_rng(value)
    a = np.clip(value + rng.normal(0, 20, (24, 32, 3)), 0, 255).astype(np.uint8)
    exif = PILImage.Exif()
    ifd = exif.get_ifd(0x8769)
    if t is not None:
        ifd[0x829A] = IFDRational(*t)
    if f_number is not None:
        ifd[0x829D] = IFDRational(*f_number)
    if iso is not None:
        ifd[0x8827] = iso
    PILImage.fromarray(a).save(path, exif=exif, quality=95)
    return str(path)


def test_read_exif_gives_the_tags_pillow_wrote(tmp_path):
    p = _jpeg(tmp_path / "a.jpg", t=(1, 250), f_number=(28, 10), iso=400)
    e = wm.load_exif(p)
    assert isinstance(e, wm.ExifInfo)
    assert (e.exposure_time, e.f_number, e.iso_speed) == (0.004, 2.8, 400.0)
    # Pillow's own reading agrees.
    ifd = PILImage.open(p).getexif().get_ifd(0x8769)
    assert float(ifd[0x829A]) == e.exposure_time and float(ifd[0x829D]) == e.f_number
    only = wm.load_exif(_jpeg(tmp_path / "b.jpg", t=(1, 30)))
    assert only.exposure_time == pytest.approx(1 / 30) and only.iso_speed is None
    plain = tmp_path / "plain.png"
    wm.save_image(plain, np.zeros((4, 4)))
    with pytest.raises(OSError, match="plain.png"):
        wm.load_exif(plain)


def test_a_real_photographs_exif_without_exposure_is_named():
    """scikit-image's Hubble image carries an EXIF block written by Photoshop, without
    exposure tags: the settings are None and a stack of it needs explicit times."""
    import skimage
    src = os.path.join(os.path.dirname(skimage.__file__), "data", "hubble_deep_field.jpg")
    e = wm.load_exif(src)
    assert (e.exposure_time, e.f_number, e.iso_speed) == (None, None, None)
    with pytest.raises(OSError, match="hubble_deep_field.jpg.*exposure times"):
        hdr.exif_exposure_times([src, src])
    assert hdr.exif_exposure_times([src, src], [0.1, 0.2]) == [0.1, 0.2]


def test_exposure_times_from_exif_and_relative_exposure(tmp_path):
    a = _jpeg(tmp_path / "a.jpg", t=(1, 100), f_number=(4, 1), iso=100)
    b = _jpeg(tmp_path / "b.jpg", t=(1, 25), f_number=(4, 1), iso=100)
    assert hdr.exif_exposure_times([a, b]) == [0.01, 0.04]
    # ISO 400 at f/8 against ISO 100 at f/4: gain 4, aperture area 1/4, the same as 0.04 s.
    c = _jpeg(tmp_path / "c.jpg", t=(1, 25), f_number=(8, 1), iso=400)
    assert hdr.exif_exposure_times([a, c]) == pytest.approx([0.01, 0.04], rel=1e-12)
    d = _jpeg(tmp_path / "d.jpg", t=(1, 100), f_number=(4, 1), iso=800)
    assert hdr.exif_exposure_times([a, d]) == pytest.approx([0.01, 0.08], rel=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert hdr.exif_exposure_times([a, b], [0.0105, 0.04]) == [0.0105, 0.04]
    with pytest.warns(UserWarning, match="b.jpg.*differs from the EXIF exposure 0.04"):
        assert hdr.exif_exposure_times([a, b], [0.01, 0.08]) == [0.01, 0.08]
    with pytest.raises(ValueError, match="one exposure time per image"):
        hdr.exif_exposure_times([a, b], [0.01])
    with pytest.raises(OSError, match="missing.jpg"):
        hdr.exif_exposure_times([a, str(tmp_path / "missing.jpg")])


def test_merge_and_calibration_read_exif_from_files(tmp_path):
    # Exact rationals 1/200, 1/50 and 2/25 s.
    paths = [_jpeg(tmp_path / f"e{k}.jpg", t=r, value=v)
             for k, (r, v) in enumerate(zip([(1, 200), (1, 50), (2, 25)], (40, 110, 200)))]
    arrays = [np.round(wm.load_image(p) * 255).astype(np.uint8) for p in paths]
    from_files, n_files = hdr.merge_stack(paths)
    from_arrays, n_arrays = hdr.merge_stack(arrays, [0.005, 0.02, 0.08])
    np.testing.assert_array_equal(from_files, from_arrays)
    assert n_files == n_arrays
    with pytest.warns(UserWarning, match="e2.jpg"):
        hdr.merge_stack(paths, [0.005, 0.02, 0.5])
    with pytest.raises(ValueError, match="exposure_times"):
        hdr.merge_stack(arrays)
    with pytest.raises(ValueError, match="mixes file paths and arrays"):
        hdr.merge_stack([paths[0], arrays[1]], [0.1, 0.2])


def test_16_bit_tiff_stacks_merge_and_calibrate_over_65536_codes(tmp_path):
    """A gamma-2.2 camera's 16-bit TIFFs (written by tifffile) of a gradient: the responses
    cover every code and merging with them recovers the radiance ratios."""
    h, w = 40, 64
    radiance = np.tile(np.geomspace(0.02, 20.0, w), (h, 1))
    times = [0.004 * 2 ** k for k in range(6)]
    paths = []
    for k, t in enumerate(times):
        codes = np.round(np.clip(radiance * t, 0, 1) ** (1 / 2.2) * 65535).astype(np.uint16)
        p = tmp_path / f"x{k}.tif"
        tifffile.imwrite(p, codes, photometric="minisblack")
        paths.append(str(p))
    table = hdr.calibrate_debevec(paths, times)
    assert table.shape[0] == 65536
    g = np.log(table.reshape(65536, -1)[:, 0])
    # ln f^-1(4 z) - ln f^-1(z) = 2.2 ln 4.
    assert abs(g[48000] - g[12000] - 2.2 * np.log(4)) < 0.15
    mn, fit = hdr.calibrate_mitsunaga_nayar(paths, times)
    assert mn.shape[0] == 65536
    merged, _ = hdr.merge_stack(paths, times, "gamma2.2")
    ratio = merged / radiance
    assert np.std(np.log(ratio)) < 0.01
    np.testing.assert_allclose(np.median(ratio), 1.0, rtol=0.01)


def test_cli_reads_exif_times_and_warns_on_mismatch(tmp_path):
    exe = os.environ.get("WSCG_BIN")
    if not exe or not os.path.exists(exe):
        pytest.skip("WSCG_BIN (the wscg binary built by cargo test) is not set")
    paths = [_jpeg(tmp_path / f"e{k}.jpg", t=r, value=v)
             for k, (r, v) in enumerate(zip([(1, 200), (1, 50), (2, 25)], (40, 110, 200)))]
    out = tmp_path / "m.exr"
    run = subprocess.run([exe, "hdr", "merge", *paths, "--out", str(out)], capture_output=True,
                         text=True, check=True)
    assert "exposure times from EXIF (s): 0.005, 0.02, 0.08" in run.stdout
    ref, _ = hdr.merge_stack(paths)
    np.testing.assert_allclose(wm.load_image(out), ref, rtol=1e-6)
    run = subprocess.run([exe, "hdr", "merge", *paths, "--times", "0.005,0.02,0.5", "--out",
                          str(tmp_path / "w.exr")], capture_output=True, text=True, check=True)
    assert "warning" in run.stderr and "e2.jpg" in run.stderr, run.stderr
    plain = tmp_path / "plain.png"
    wm.save_image(plain, np.zeros((4, 4)))
    bad = subprocess.run([exe, "hdr", "merge", paths[0], str(plain), "--out",
                          str(tmp_path / "x.exr")], capture_output=True, text=True)
    assert bad.returncode != 0 and "plain.png" in bad.stderr
