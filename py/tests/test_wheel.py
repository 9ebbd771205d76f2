"""The wheel a cluster installs (README, "Wheels"): scripts/build_wheel.py builds one abi3
wheel, manylinux2014, with the `wscg` program inside; it installs into a fresh virtualenv of
every CPython (3.9 or later) on the machine, where `import wscg` and the `wscg --version`
command work.

Builds with cargo's debug profile (the release build takes many minutes); skipped, with the
reason, where maturin, ziglang or cargo is missing. Marked slow (a second link of the program
and the extension through zig, minutes on two cores), so the main pytest run leaves it out:
scripts/test runs it as its last step, `pytest -m wheel`."""

from __future__ import annotations

import configparser
import glob
import importlib.util
import os
import pathlib
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

import wscg

ROOT = pathlib.Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.wheel, pytest.mark.slow]


def _pythons():
    """CPython interpreters of the machine, 3.9 or later, one per version: the system's, and
    those that pyenv installed."""
    found = {}
    pyenv = os.environ.get("PYENV_ROOT", os.path.expanduser("~/.pyenv"))
    for p in sorted(glob.glob("/usr/bin/python3.*") + glob.glob("/usr/local/bin/python3.*")
                    + glob.glob(os.path.join(pyenv, "versions", "*", "bin", "python3.*"))
                    + [sys.executable]):
        if not re.search(r"python3\.\d+$", p) and p != sys.executable:
            continue
        r = subprocess.run([p, "-c", "import sys, venv; print('%d.%d' % sys.version_info[:2])"],
                           capture_output=True, text=True)
        if r.returncode:
            continue
        version = tuple(map(int, r.stdout.strip().split(".")))
        if version >= (3, 9):
            found.setdefault(version, p)
    return [found[v] for v in sorted(found)]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    for module, why in (("maturin", "pip install maturin"), ("ziglang", "pip install ziglang")):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"building the wheel needs {module} ({why})")
    if shutil.which("cargo") is None:
        pytest.skip("building the wheel needs cargo")
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import build_wheel
    finally:
        sys.path.pop(0)
    return build_wheel.build(release=False, out=tmp_path_factory.mktemp("dist"))


def test_the_wheel_is_abi3_and_carries_the_program(wheel):
    name = wheel.name
    assert "-cp39-abi3-" in name, name
    assert "manylinux_2_17" in name or "manylinux2014" in name, name
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        entry = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
        scripts = configparser.ConfigParser()
        scripts.read_string(z.read(entry).decode())
        assert scripts["console_scripts"]["wscg"].strip() == "wscg._cli:main"
    assert "wscg/_bin/wscg" in names
    assert any(n.startswith("wscg/_native") and n.endswith(".abi3.so") for n in names)


def test_auditwheel_reports_manylinux2014(wheel):
    if importlib.util.find_spec("auditwheel") is None:
        pytest.skip("auditwheel is not installed (pip install auditwheel)")
    r = subprocess.run([sys.executable, "-m", "auditwheel", "show", str(wheel)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())
    assert re.search(r'consistent with the following platform tag: "manylinux_2_17_\w+"',
                     text), r.stdout


@pytest.mark.parametrize("python", _pythons())
def test_the_wheel_installs_and_runs(wheel, python, tmp_path):
    env_dir = tmp_path / "venv"
    subprocess.run([python, "-m", "venv", str(env_dir)], check=True)
    py = env_dir / "bin" / "python"
    r = subprocess.run([str(py), "-m", "pip", "install", "--quiet",
                        "--disable-pip-version-check", str(wheel)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    r = subprocess.run([str(py), "-c", "import wscg, wscg.distributed; print(wscg.__version__)"],
                       capture_output=True, text=True, cwd=tmp_path, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == wscg.__version__
    r = subprocess.run([str(env_dir / "bin" / "wscg"), "--version"], capture_output=True,
                       text=True, cwd=tmp_path, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"wscg {wscg.__version__}"
