import numpy as np
import pytest

import wscg
import wscg.math as wm
from results_check import check_result


def test_version_and_docstrings():
    assert isinstance(wscg.__version__, str) and wscg.__version__.count(".") == 2
    for name in wm.__all__:
        obj = getattr(wm, name)
        # Functions document their parameters, result classes their fields.
        section = "Attributes" if isinstance(obj, type) else "Parameters"
        assert obj.__doc__ and section in obj.__doc__, name


def test_image_round_trips(tmp_path, astronaut):
    img = astronaut[:40, :50]
    p8 = tmp_path / "a.png"
    wm.save_image(p8, img)
    back = wm.load_image(p8)
    assert back.dtype == np.float32 and back.shape == img.shape
    assert np.max(np.abs(back - img)) <= 0.5 / 255 + 1e-6
    p16 = tmp_path / "b.png"
    wm.save_image(str(p16), img[..., 0], bit_depth=16)
    back16 = wm.load_image(p16)
    assert back16.shape == (40, 50)
    assert np.max(np.abs(back16 - img[..., 0])) <= 0.5 / 65535 + 1e-7
    exr = tmp_path / "c.exr"
    wm.save_image(exr, img * 30)
    assert np.allclose(wm.load_image(exr), img * 30, rtol=1e-6)
    from skimage import io
    assert np.array_equal(io.imread(p8), np.round(np.clip(img, 0, 1) * 255).astype(np.uint8))


def test_image_errors(tmp_path):
    with pytest.raises(OSError):
        wm.load_image(tmp_path / "missing.png")
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not an image")
    with pytest.raises(OSError):
        wm.load_image(bad)
    with pytest.raises(OSError, match="extension"):
        wm.save_image(tmp_path / "x.bmp", np.zeros((4, 4)))
    with pytest.raises(ValueError, match="bit_depth"):
        wm.save_image(tmp_path / "x.png", np.zeros((4, 4)), bit_depth=12)
    with pytest.raises(ValueError):
        wm.save_image(tmp_path / "x.png", np.full((4, 4), np.nan))


@pytest.mark.parametrize("name", ["v.nii", "v.nii.gz", "v.npy"])
def test_volume_round_trip_keeps_axis_order_and_spacing(tmp_path, name):
    vol = np.arange(3 * 4 * 5, dtype=np.float32).reshape(3, 4, 5)  # [z, y, x]
    p = tmp_path / name
    wm.save_volume(p, vol, spacing=(2.5, 1.5, 0.5))
    back, spacing = wm.load_volume(p)
    assert back.shape == (3, 4, 5) and np.array_equal(back, vol)
    if name != "v.npy":
        assert np.allclose(spacing, (2.5, 1.5, 0.5))
    if name == "v.npy":
        assert np.array_equal(np.load(p), vol)


def test_nifti_written_by_us_is_x_fastest(tmp_path):
    vol = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    p = tmp_path / "v.nii"
    wm.save_volume(p, vol)
    raw = np.frombuffer(p.read_bytes()[352:], dtype="<f4")
    assert np.array_equal(raw, vol.ravel())  # [z, y, x] C order == x fastest


def test_raw_volume(tmp_path):
    data = np.arange(2 * 3 * 4, dtype="<u2").reshape(2, 3, 4)
    p = tmp_path / "v.raw"
    p.write_bytes(data.tobytes())
    vol, spacing = wm.load_raw_volume(p, (2, 3, 4), "u16le", spacing=(3.0, 2.0, 1.0))
    assert np.array_equal(vol, data.astype(np.float32)) and spacing == (3.0, 2.0, 1.0)
    with pytest.raises(OSError, match="truncated"):
        wm.load_raw_volume(p, (2, 3, 5), "u16le")
    with pytest.raises(ValueError, match="raw type"):
        wm.load_raw_volume(p, (2, 3, 4), "u17")


def test_volume_errors(tmp_path):
    with pytest.raises(OSError):
        wm.load_volume(tmp_path / "missing.nii")
    bad = tmp_path / "bad.nii"
    bad.write_bytes(b"\0" * 100)
    with pytest.raises(OSError):
        wm.load_volume(bad)
    np.save(tmp_path / "flat.npy", np.zeros((3, 3)))
    with pytest.raises(OSError):
        wm.load_volume(tmp_path / "flat.npy")
    with pytest.raises(OSError, match="unsupported"):
        wm.load_volume(tmp_path / "v.mha")
    with pytest.raises(ValueError, match="3-D"):
        wm.save_volume(tmp_path / "v.npy", np.zeros((2, 2)))
    with pytest.raises(ValueError, match="spacing"):
        wm.save_volume(tmp_path / "v.npy", np.zeros((2, 2, 2)), spacing=(1, 0, 1))


@pytest.mark.parametrize("name,binary", [("m.obj", True), ("m.ply", True), ("m.ply", False)])
def test_mesh_round_trip(tmp_path, name, binary):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) * 0.7
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    c = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0.5]], dtype=np.float32)
    p = tmp_path / name
    wm.save_mesh(p, v, f, colors=c, binary=binary)
    m = wm.load_mesh(p)
    assert np.allclose(m.vertices, v) and np.array_equal(m.faces, f)
    assert np.max(np.abs(m.colors - c)) <= 0.5 / 255 + 1e-6
    assert m.normals is None
    text = check_result(m, wm.Mesh)
    assert "vertices=array(shape=(4, 3), dtype=float64)" in text and "normals=None" in text


def test_mesh_errors(tmp_path):
    v = np.zeros((3, 3))
    with pytest.raises(ValueError, match="faces"):
        wm.save_mesh(tmp_path / "m.obj", v, np.array([[0, 1, 5]]))
    with pytest.raises(ValueError, match="faces"):
        wm.save_mesh(tmp_path / "m.obj", v, np.array([[0, 1, -1]]))
    with pytest.raises(ValueError, match="vertices"):
        wm.save_mesh(tmp_path / "m.obj", np.zeros((3, 2)), np.array([[0, 1, 2]]))
    with pytest.raises(OSError):
        wm.load_mesh(tmp_path / "missing.ply")
    bad = tmp_path / "bad.ply"
    bad.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 1000000000000\nend_header\n")
    with pytest.raises(OSError):
        wm.load_mesh(bad)
    with pytest.raises(OSError):
        wm.save_mesh(tmp_path / "m.stl", np.eye(3), np.array([[0, 1, 2]]))


@pytest.mark.parametrize("name", ["rocket.jpg", "retina.jpg", "hubble_deep_field.jpg"])
def test_truncated_photographs_are_refused(tmp_path, name):
    """Camera JPEGs shipped with scikit-image: the whole file loads as OpenCV decodes it; the
    same file cut short (an interrupted download) is an error naming it, not a picture with
    a grey block."""
    import os

    import cv2
    import skimage

    src = os.path.join(os.path.dirname(skimage.__file__), "data", name)
    data = open(src, "rb").read()
    whole = wm.load_image(src)
    ref = cv2.cvtColor(cv2.imread(src, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB) / 255.0
    assert whole.shape == ref.shape
    # Two JPEG decoders differ by their IDCT and upsampling, by a few grey levels.
    assert np.abs(whole - ref).mean() < 0.01
    for cut in (len(data) // 2, len(data) * 9 // 10, len(data) - 2):
        p = tmp_path / f"cut_{cut}_{name}"
        p.write_bytes(data[:cut])
        with pytest.raises((OSError, ValueError), match="truncated JPEG") as e:
            wm.load_image(p)
        assert p.name in str(e.value)
