"""Writers and panics: every writer of the package writes atomically and reports a failed
write as OSError naming the file (a full disk is simulated in a subprocess by a file-size
limit with SIGXFSZ ignored, so writes fail with EFBIG); a Rust panic reaches Python as a
RuntimeError, never as pyo3's PanicException (a BaseException)."""

import inspect
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import wscg
from wscg import _native
from wscg import motion

# Every writer of the package: name -> code that writes `path` (a file or, for folder
# writers, a folder) in the subprocess below, and the file in it to check.
WRITERS = {
    "math.save_image": ("wm.save_image(path, rng.random((64, 64)))", None),
    "math.save_volume": ("wm.save_volume(path, rng.random((16, 16, 16)))", None),
    "math.save_mesh": ("wm.save_mesh(path, *mesh)", None),
    "motion.save_bvh": ("motion.save_bvh(path, np.zeros((40, 51)), np.zeros(40))", None),
    "gait.save_skeleton_csv": ("gait.save_skeleton_csv(path, rng.random((20, 25, 3)))", None),
    "video.save_frames": (
        "video.save_frames(path, (rng.random((2, 32, 32)) * 255).astype(np.uint8))",
        "frame_00000.png",
    ),
    "octree.HybridOctree.save": ("octree.build(*mesh, depth=3).save(path)", None),
    "biometrics.PerClassSFA.save": ("sfa(B.PerClassSFA(pca_n_components=6, m=2)).save(path)",
                                    None),
    "biometrics.GlobalSFA.save": (
        "sfa(B.GlobalSFA(pca_n_components=6, n_components=2)).save(path)", None),
    "raytrace.save_paint": (
        "raytrace.save_paint(path, raytrace.PaintDescription(radius_um=26.0, density=7.3,"
        " seed=1))", None),
    "motion.save_dataset": (
        "motion.save_dataset(path, motion.make_synthetic_dataset(n_trials=4, n_samples=50))",
        "angles.npy",
    ),
    "doe.save_study": (
        "doe.save_study(path, doe.Study(['s1', 's2'], ['a', 'b'], rng.random((2, 2, 3))))",
        None,
    ),
    "doe.save_runs": ("doe.save_runs(path, rng.random((4, 3)), rng.random(4))", None),
    "hdr.save_crf": ("hdr.save_crf(path, np.linspace(0.0, 1.0, 256 * 3).reshape(256, 3))",
                     None),
    "hdr.save_exposure_times": ("hdr.save_exposure_times(path, [0.001, 0.01, 0.1, 1.0, 2.0, 4.0])",
                                None),
}

SUFFIX = {"math.save_image": ".png", "math.save_volume": ".nii", "math.save_mesh": ".obj",
          "motion.save_bvh": ".bvh", "gait.save_skeleton_csv": ".csv",
          "raytrace.save_paint": ".json", "doe.save_study": ".csv", "doe.save_runs": ".csv",
          "hdr.save_crf": ".csv", "hdr.save_exposure_times": ".txt"}

CHILD = textwrap.dedent("""
    import json, resource, signal, sys
    import numpy as np
    import wscg.math as wm
    from wscg import biometrics as B, doe, gait, hdr, motion, octree, raytrace, video

    rng = np.random.default_rng(0)
    g = np.stack(np.meshgrid(np.arange(8.0), np.arange(8.0), indexing="ij"), -1).reshape(-1, 2)
    verts = np.c_[g, rng.random(64)]
    faces = np.array([[i * 8 + j, i * 8 + j + 1, i * 8 + j + 8] for i in range(7)
                      for j in range(7)])
    mesh = (verts, faces)

    def sfa(model):
        X = rng.random((60, 12))
        y = np.repeat(np.arange(3), 20)
        return model.fit(X, y)

    cases = json.loads(sys.argv[1])
    # The models and meshes above are built before the limit: only the writes must fail.
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (16, resource.RLIM_INFINITY))
    out = {}
    for name, (code, path) in cases.items():
        try:
            exec(code, dict(globals(), path=path))
            out[name] = ["no error", ""]
        except BaseException as e:
            out[name] = [type(e).__name__, str(e)]
    print(json.dumps(out))
""")


def _public_writers():
    """Public functions and methods of every submodule whose name says they write a file."""
    found = set()
    writes = ("save", "write")
    for modname in wscg.__all__:
        mod = getattr(wscg, modname)
        if not inspect.ismodule(mod):
            continue
        short = mod.__name__.removeprefix("wscg.")
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name)
            if inspect.isclass(obj):
                for attr in dir(obj):
                    if attr.startswith(writes) and callable(getattr(obj, attr)):
                        found.add(f"{short}.{name}.{attr}")
            elif callable(obj) and name.startswith(writes):
                found.add(f"{short}.{name}")
    return found


def test_every_writer_is_covered():
    assert _public_writers() == set(WRITERS)


def test_a_full_disk_raises_oserror_and_keeps_the_previous_file(tmp_path):
    old = b"previous content"
    cases, targets = {}, {}
    for name, (code, inner) in WRITERS.items():
        path = tmp_path / (name.replace(".", "_") + SUFFIX.get(name, ".bin"))
        if inner:
            path.mkdir()
            target = path / inner
        else:
            target = path
        target.write_bytes(old)
        cases[name] = [code, str(path)]
        targets[name] = target
    child = subprocess.run([sys.executable, "-c", CHILD, json.dumps(cases)],
                           capture_output=True, text=True, timeout=300)
    assert child.returncode == 0, child.stderr
    results = json.loads(child.stdout.strip().splitlines()[-1])
    for name, target in targets.items():
        kind, message = results[name]
        assert kind == "OSError", f"{name}: {kind} {message}"
        assert target.name in message or target.parent.name in message, f"{name}: {message}"
        assert target.read_bytes() == old, f"{name} lost the previous file"
        leftovers = [p for p in target.parent.iterdir() if p.name.startswith("wscg_tmp")]
        assert not leftovers, f"{name} left {leftovers}"


def test_a_panic_is_a_runtime_error_with_its_message():
    with pytest.raises(RuntimeError, match="boom in the test hook"):
        _native._panic_in_detach_for_tests("boom in the test hook")
    try:
        _native._panic_in_detach_for_tests("caught by except Exception")
    except Exception as e:  # noqa: BLE001 - the point: a panic is an Exception
        assert "caught by except Exception" in str(e)
    # The pool still works after a panic.
    assert wscg.math.mse(np.zeros(4), np.ones(4)) == 1.0


def test_a_bvh_whose_frame_count_overflows_is_an_oserror_naming_the_file(tmp_path):
    good = tmp_path / "good.bvh"
    motion.save_bvh(good, np.zeros((2, 51)), np.zeros(2))
    text = good.read_text()
    assert "Frames: 2" in text
    # 54 channels per frame: (2^63 + 2) x 54 wraps around to the 108 values in the file.
    for frames in ("9223372036854775810", "18446744073709551615"):
        bad = tmp_path / "huge.bvh"
        bad.write_text(text.replace("Frames: 2", f"Frames: {frames}"))
        with pytest.raises(OSError, match="huge.bvh"):
            motion.load_bvh(bad)
    assert motion.load_bvh(good).angles.shape[0] == 2
