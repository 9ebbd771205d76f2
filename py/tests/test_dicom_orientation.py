"""Real data: DICOM series and NIfTI orientation kept end to end.

References nobody here wrote: pydicom's test files (CT and MR slices in many transfer
syntaxes) and its decoders, nibabel's test NIfTI files and its affine reader. Series with
known geometry are written by pydicom in the tests (shuffled, oblique, with a missing slice,
two series, mixed sizes)."""

import os
import pickle
import subprocess

import numpy as np
import pytest

from wscg import math as wm

pydicom = pytest.importorskip("pydicom")
nib = pytest.importorskip("nibabel")

from pydicom.dataset import FileDataset, FileMetaDataset  # noqa: E402
from pydicom.uid import ExplicitVRLittleEndian, generate_uid  # noqa: E402

NIB_DATA = os.path.join(os.path.dirname(nib.__file__), "tests", "data")
DCM_DATA = os.path.join(os.path.dirname(pydicom.__file__), "data", "test_files")


def get_testdata_file(name):
    """A test file shipped in pydicom's wheel (never one it would download)."""
    path = os.path.join(DCM_DATA, name)
    if not os.path.exists(path):
        pytest.skip(f"{name} is not in pydicom's wheel")
    return path

# Encodings of pydicom's test files; the lossless ones also equal their native original.
ENCODINGS = [
    ("CT_small.dcm", None),
    ("MR_small.dcm", None),
    ("MR_small_implicit.dcm", "MR_small.dcm"),
    ("MR_small_bigendian.dcm", "MR_small.dcm"),
    ("MR_small_expb.dcm", "MR_small.dcm"),
    ("MR_small_RLE.dcm", "MR_small.dcm"),
    ("MR_small_jp2klossless.dcm", "MR_small.dcm"),
    ("JPEG2000.dcm", None),
    ("image_dfl.dcm", None),
    ("693_J2KI.dcm", None),
]
# JPEG-LS needs CharLS (C++), not built here: the error names the transfer syntax.
UNSUPPORTED = [("MR_small_jpeg_ls_lossless.dcm", "1.2.840.10008.1.2.4.80"),
               ("JPEGLSNearLossless_16.dcm", "1.2.840.10008.1.2.4.81"),
               # 12-bit JPEG (process 4): jpeg-decoder reads 8-bit JPEG only.
               ("JPGExtended.dcm", "1.2.840.10008.1.2.4.51"),
               ("JPEG-lossy.dcm", "1.2.840.10008.1.2.4.51"),
               # 32-bit samples: dicom-pixeldata converts 1, 8 and 16 bits only.
               ("liver_1frame.dcm", "BitsAllocated")]


def _hu(ds):
    """pydicom's pixel values with the modality rescale (HU for CT)."""
    slope = float(getattr(ds, "RescaleSlope", 1.0))
    intercept = float(getattr(ds, "RescaleIntercept", 0.0))
    return ds.pixel_array.astype(np.float64) * slope + intercept


def _reference(name, lossless_of):
    """pydicom's decoding of ``name``; where pydicom has no decoder for it here, that of the
    native file it encodes losslessly; else None."""
    ds = pydicom.dcmread(get_testdata_file(name))
    try:
        return _hu(ds)
    except Exception:  # no pydicom decoder plugin for this transfer syntax
        if lossless_of is None:
            return None
        return _hu(pydicom.dcmread(get_testdata_file(lossless_of)))


@pytest.mark.parametrize("name,lossless_of", ENCODINGS)
def test_dicom_values_equal_pydicom(name, lossless_of):
    path = get_testdata_file(name)
    want = _reference(name, lossless_of)
    if want is None:
        pytest.skip(f"pydicom has no decoder for {name} here")
    got = wm.load_volume(path)
    assert got.volume.shape == (1,) + want.shape
    tol = 1e-3 * max(1.0, np.abs(want).max()) if "lossy" in name else 0.0
    np.testing.assert_allclose(got.volume[0], want, rtol=0, atol=tol)


@pytest.mark.parametrize("name,uid", UNSUPPORTED)
def test_dicom_undecodable_transfer_syntax_is_named(name, uid):
    with pytest.raises(OSError, match=uid.replace(".", r"\.")):
        wm.load_volume(get_testdata_file(name))


def test_dicom_jpeg_baseline_equals_pydicom(tmp_path):
    """8-bit greyscale JPEG baseline (pydicom's wheel has colour ones only): CT_small's pixels
    scaled to 8 bits, compressed by Pillow and encapsulated by pydicom."""
    PIL = pytest.importorskip("PIL.Image")
    import io
    from pydicom.encaps import encapsulate
    from pydicom.uid import JPEGBaseline8Bit

    ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    px = ds.pixel_array.astype(np.float64)
    grey = np.round(255 * (px - px.min()) / (px.max() - px.min())).astype(np.uint8)
    buf = io.BytesIO()
    PIL.fromarray(grey).save(buf, format="JPEG", quality=90)
    ds.file_meta.TransferSyntaxUID = JPEGBaseline8Bit
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
    ds.PixelData = encapsulate([buf.getvalue()])
    ds["PixelData"].VR = "OB"
    ds.RescaleSlope, ds.RescaleIntercept = 4, -1000
    ds.save_as(tmp_path / "jpeg.dcm")
    ref = pydicom.dcmread(tmp_path / "jpeg.dcm")
    try:
        want = _hu(ref)
    except Exception:
        pytest.skip("pydicom has no JPEG decoder here")
    got = wm.load_volume(tmp_path / "jpeg.dcm")
    # Lossy JPEG decoders may differ by one code value (IDCT rounding, ITU T.81 Annex A.3.5
    # bounds the IDCT error, not its rounding): at most 1 code (4 HU), and rarely.
    codes = np.abs(got.volume[0] - want) / 4.0
    assert codes.max() <= 1.0
    assert codes.mean() < 0.05


def test_ct_small_is_in_hounsfield_units_with_its_geometry():
    path = get_testdata_file("CT_small.dcm")
    ds = pydicom.dcmread(path)
    got = wm.load_volume(path)
    assert float(ds.RescaleIntercept) != 0.0
    dy, dx = (float(v) for v in ds.PixelSpacing)
    assert got.spacing[1:] == pytest.approx((dy, dx))
    assert got.has_affine
    # Voxel (i, j) = (column, row) at IPP + i dx r + j dy c in LPS, x and y negated for RAS.
    r, c = np.array(ds.ImageOrientationPatient[:3]), np.array(ds.ImageOrientationPatient[3:])
    ipp = np.array([float(v) for v in ds.ImagePositionPatient])
    lps = ipp + 5 * dx * r + 7 * dy * c
    ras = got.affine @ [5, 7, 0, 1]
    np.testing.assert_allclose(ras[:3], lps * [-1, -1, 1], atol=1e-9)
    assert got.origin == pytest.approx(tuple((ipp * [-1, -1, 1])[::-1]))
    volume, spacing = got          # unpacks as before
    assert volume is got.volume and spacing == got.spacing
    back = pickle.loads(pickle.dumps(got))
    assert back == got


def _series(folder, n=6, shape=(12, 10), spacing=(0.8, 0.6), step=2.5, oblique=True,
            uid=None, skip=(), start=0, sizes=None, description="test series"):
    """Writes ``n`` single-slice CT files with known geometry; returns (volume [k, j, i] in
    HU, affine RAS)."""
    os.makedirs(folder, exist_ok=True)
    if oblique:
        a, b = np.deg2rad(20.0), np.deg2rad(-35.0)
        r = np.array([np.cos(a), np.sin(a), 0.0])
        c = np.array([-np.sin(a) * np.cos(b), np.cos(a) * np.cos(b), np.sin(b)])
    else:
        r, c = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    normal = np.cross(r, c)
    p0 = np.array([-30.5, 12.25, 80.0])
    uid = uid or generate_uid()
    rng = np.random.default_rng(len(os.listdir(folder)))
    stored = []
    for k in range(n):
        rows, cols = sizes[k] if sizes else shape
        raw = rng.integers(0, 4000, size=(rows, cols)).astype(np.uint16)
        stored.append(raw.astype(np.float64) * 1.0 - 1024.0)
        if k in skip:
            continue
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        fname = os.path.join(folder, f"s{start + k:03d}_{rng.integers(1e9)}.dcm")
        ds = FileDataset(fname, {}, file_meta=meta, preamble=b"\0" * 128)
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.Modality = "CT"
        ds.SeriesInstanceUID = uid
        ds.SeriesDescription = description
        ds.Rows, ds.Columns = rows, cols
        ds.PixelSpacing = [spacing[0], spacing[1]]
        ds.ImageOrientationPatient = [float(v) for v in np.concatenate([r, c])]
        ds.ImagePositionPatient = [float(v) for v in p0 + k * step * normal]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 16, 16, 15
        ds.PixelRepresentation = 0
        ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
        ds.PixelData = raw.tobytes()
        ds.save_as(fname, enforce_file_format=True)
    dy, dx = spacing
    lps = np.eye(4)
    lps[:3, 0], lps[:3, 1], lps[:3, 2], lps[:3, 3] = r * dx, c * dy, normal * step, p0
    ras = np.diag([-1.0, -1.0, 1.0, 1.0]) @ lps
    return (np.stack(stored) if not sizes else None), ras


def test_dicom_series_shuffled_oblique(tmp_path):
    want, affine = _series(tmp_path / "ct")
    got = wm.load_volume(tmp_path / "ct")      # file names are in random order
    np.testing.assert_array_equal(got.volume, want.astype(np.float32))
    np.testing.assert_allclose(got.affine, affine, atol=1e-9)
    assert got.spacing == pytest.approx((2.5, 0.8, 0.6))
    files = sorted(os.listdir(tmp_path / "ct"))
    single = wm.load_volume(tmp_path / "ct" / files[0])
    assert single.volume.shape == (1, 12, 10)


def test_dicom_series_errors_name_the_slices(tmp_path):
    _series(tmp_path / "gap", skip=(3,))
    with pytest.raises(ValueError, match="missing slices"):
        wm.load_volume(tmp_path / "gap")
    uid_a, uid_b = generate_uid(), generate_uid()
    _series(tmp_path / "two", n=3, uid=uid_a, description="first")
    _series(tmp_path / "two", n=4, uid=uid_b, description="second", start=10)
    with pytest.raises(ValueError, match="2 series") as e:
        wm.load_volume(tmp_path / "two")
    assert uid_a in str(e.value) and uid_b in str(e.value)
    assert wm.load_volume(tmp_path / "two", series=uid_b).volume.shape == (4, 12, 10)
    _series(tmp_path / "sizes", n=3, sizes=[(12, 10), (12, 10), (12, 11)])
    with pytest.raises(ValueError, match="mixed sizes"):
        wm.load_volume(tmp_path / "sizes")
    # Uneven steps: one slice moved by 0.3 of a step.
    _series(tmp_path / "uneven", n=5)
    f = sorted(os.listdir(tmp_path / "uneven"))
    ds = [pydicom.dcmread(tmp_path / "uneven" / n) for n in f]
    ds.sort(key=lambda d: float(d.ImagePositionPatient[2]))
    mid = ds[2]
    p = np.array([float(v) for v in mid.ImagePositionPatient])
    normal = np.cross(np.array(mid.ImageOrientationPatient[:3], float),
                      np.array(mid.ImageOrientationPatient[3:], float))
    mid.ImagePositionPatient = [float(v) for v in p + 0.3 * 2.5 * normal]
    mid.save_as(mid.filename)
    with pytest.raises(ValueError, match="non-uniform slice spacing") as e:
        wm.load_volume(tmp_path / "uneven")
    assert os.path.basename(mid.filename) in str(e.value)


def test_dicom_bad_files(tmp_path):
    src = open(get_testdata_file("CT_small.dcm"), "rb").read()
    (tmp_path / "trunc.dcm").write_bytes(src[:len(src) // 2])
    with pytest.raises(OSError):
        wm.load_volume(tmp_path / "trunc.dcm")
    bad = bytearray(src)
    bad[128:132] = b"XXXX"
    (tmp_path / "magic.dcm").write_bytes(bytes(bad))
    with pytest.raises(OSError, match="DICM"):
        wm.load_volume(tmp_path / "magic.dcm")
    # A header declaring 65535 x 65535 x 2^30 frames is refused before any pixel is decoded.
    ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    ds.Rows = ds.Columns = 65535
    ds.NumberOfFrames = 1 << 30
    ds.save_as(tmp_path / "huge.dcm")
    with pytest.raises((MemoryError, ValueError, OSError), match="limit|memory"):
        wm.load_volume(tmp_path / "huge.dcm")
    (tmp_path / "empty").mkdir()
    with pytest.raises(OSError, match="no DICOM"):
        wm.load_volume(tmp_path / "empty")


NIFTIS = ["anatomical.nii", "standard.nii.gz", "reoriented_anat_moved.nii",
          "resampled_anat_moved.nii"]


@pytest.mark.parametrize("name", NIFTIS)
def test_nifti_affine_equals_nibabels(name):
    path = os.path.join(NIB_DATA, name)
    img = nib.load(path)
    got = wm.load_volume(path)
    hdr = img.header
    if hdr["sform_code"] > 0 or hdr["qform_code"] > 0:
        assert got.has_affine
        np.testing.assert_allclose(got.affine, img.affine, rtol=0, atol=1e-5)
    np.testing.assert_array_equal(got.volume, np.asarray(img.dataobj, np.float32).T
                                  if img.ndim == 3 else got.volume)


def test_four_d_nifti_is_refused():
    with pytest.raises(OSError, match="only 3-D"):
        wm.load_volume(os.path.join(NIB_DATA, "example4d.nii.gz"))


def _oblique_nifti(path):
    """nibabel writes anatomical.nii's voxels with an oblique, flipped affine."""
    img = nib.load(os.path.join(NIB_DATA, "anatomical.nii"))
    data = np.asarray(img.dataobj, np.float32)
    t = np.deg2rad(25.0)
    rot = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])
    rot = rot @ np.array([[1, 0, 0], [0, np.cos(0.4), -np.sin(0.4)], [0, np.sin(0.4), np.cos(0.4)]])
    affine = np.eye(4)
    affine[:3, :3] = rot @ np.diag([-2.0, 2.0, 2.2])
    affine[:3, 3] = [40.0, -70.5, 12.0]
    out = nib.Nifti1Image(data, affine)
    out.set_qform(affine, code=1)
    out.set_sform(affine, code=1)
    nib.save(out, path)
    return data, nib.load(path).affine


def test_save_volume_writes_the_affine_back(tmp_path):
    data, affine = _oblique_nifti(tmp_path / "obl.nii")
    got = wm.load_volume(tmp_path / "obl.nii")
    np.testing.assert_allclose(got.affine, affine, atol=1e-5)
    wm.save_volume(tmp_path / "copy.nii.gz", got.volume, affine=got.affine)
    back = nib.load(tmp_path / "copy.nii.gz")
    np.testing.assert_allclose(back.affine, affine, atol=1e-4)
    np.testing.assert_allclose(back.get_qform(), affine, atol=1e-4)
    np.testing.assert_array_equal(np.asarray(back.dataobj).T, got.volume)
    with pytest.raises(ValueError, match="spacing"):
        wm.save_volume(tmp_path / "bad.nii", got.volume, spacing=(1, 1, 1), affine=got.affine)
    with pytest.raises(ValueError, match="affine"):
        wm.save_volume(tmp_path / "bad.nii", got.volume, affine=np.zeros((4, 4)))


def _exe():
    exe = os.environ.get("WSCG_BIN")
    if not exe or not os.path.exists(exe):
        pytest.skip("WSCG_BIN (the wscg binary) is not set")
    return exe


def test_cli_outputs_keep_the_oblique_geometry(tmp_path):
    exe = _exe()
    data, affine = _oblique_nifti(tmp_path / "ct.nii")
    seeds = np.zeros_like(data)
    bone = data > np.percentile(data, 80)
    idx = np.argwhere(bone)
    seeds[tuple(idx[0])] = 1
    seeds[tuple(idx[-1])] = 2
    nib.save(nib.Nifti1Image(seeds, affine), tmp_path / "seeds.nii")
    t_bone = float(np.percentile(data, 80))
    subprocess.run([exe, "volseg", "split", str(tmp_path / "ct.nii"), "--seeds",
                    str(tmp_path / "seeds.nii"), "--t-bone", str(t_bone), "--out",
                    str(tmp_path / "labels.nii.gz"), "--meshes", str(tmp_path / "m")],
                   check=True, capture_output=True)
    labels = nib.load(tmp_path / "labels.nii.gz")
    np.testing.assert_allclose(labels.affine, affine, atol=1e-4)
    assert labels.shape == data.shape

    level = float(np.percentile(data, 60))
    out = subprocess.run([exe, "isosurface", "extract", str(tmp_path / "ct.nii"), "--iso",
                          str(level), "--normals", "none", "--out", str(tmp_path / "s.ply")],
                         check=True, capture_output=True, text=True)
    assert "RAS" in out.stdout
    mesh = wm.load_mesh(tmp_path / "s.ply")
    # The same surface in voxel positions: an unoriented copy of the volume (no affine).
    np.save(tmp_path / "ct.npy", data.T)
    subprocess.run([exe, "isosurface", "extract", str(tmp_path / "ct.npy"), "--iso", str(level),
                    "--normals", "none", "--out", str(tmp_path / "v.ply")], check=True,
                   capture_output=True)
    voxel = wm.load_mesh(tmp_path / "v.ply").vertices
    want = nib.affines.apply_affine(affine, voxel)
    np.testing.assert_allclose(mesh.vertices, want, atol=1e-4)
    assert len(mesh.faces) == len(wm.load_mesh(tmp_path / "v.ply").faces)

    # The label meshes of `volseg split --meshes` lie on the scan too: the same split of the
    # unoriented copy gives the voxel-space meshes, which the affine must carry onto them.
    np.save(tmp_path / "seeds.npy", seeds.T)
    subprocess.run([exe, "volseg", "split", str(tmp_path / "ct.npy"), "--seeds",
                    str(tmp_path / "seeds.npy"), "--t-bone", str(t_bone), "--out",
                    str(tmp_path / "labels.npy"), "--meshes", str(tmp_path / "mv")],
                   check=True, capture_output=True)
    written = sorted(p.name for p in (tmp_path / "m").iterdir())
    assert written == sorted(p.name for p in (tmp_path / "mv").iterdir())
    assert written, "volseg split --meshes wrote no mesh"
    for name in written:
        world = wm.load_mesh(tmp_path / "m" / name)
        voxel = wm.load_mesh(tmp_path / "mv" / name)
        assert len(world.faces) == len(voxel.faces) > 0
        np.testing.assert_allclose(world.vertices,
                                   nib.affines.apply_affine(affine, voxel.vertices), atol=1e-3)


def test_cli_reads_a_dicom_folder(tmp_path):
    exe = _exe()
    want, affine = _series(tmp_path / "ct", n=5, shape=(16, 14))
    level = float(np.median(want))
    subprocess.run([exe, "isosurface", "extract", str(tmp_path / "ct"), "--iso", str(level),
                    "--normals", "none", "--out", str(tmp_path / "s.obj")], check=True,
                   capture_output=True)
    np.save(tmp_path / "ct.npy", want.astype(np.float32))
    subprocess.run([exe, "isosurface", "extract", str(tmp_path / "ct.npy"), "--iso", str(level),
                    "--normals", "none", "--out", str(tmp_path / "v.obj")], check=True,
                   capture_output=True)
    got = wm.load_mesh(tmp_path / "s.obj").vertices
    voxel = wm.load_mesh(tmp_path / "v.obj").vertices
    np.testing.assert_allclose(got, nib.affines.apply_affine(affine, voxel), atol=1e-4)
