"""The hand-written stubs (``wscg/*.pyi``) agree with the modules at run time, checked by
mypy's stubtest: every public name of a module is in its stub and the reverse, every
function takes the parameters its stub names (kinds, order and defaults), every class has
the methods and properties its stub lists, read-only properties are properties in the stub
and native classes that cannot be subclassed are ``@final``. mypy's options for the run are
in ``stubtest.ini`` beside this file; no entry needs an allowlist.

test_api_conventions.py checks the parameter names and literal defaults of the same stubs;
this check adds the names a stub lacks or invents, the parameter kinds, the classes' members
and the module attributes."""

from __future__ import annotations

import importlib.util
import os
import pathlib
import subprocess
import sys

import pytest

CONFIG = pathlib.Path(__file__).with_name("stubtest.ini")


def test_stubtest(tmp_path):
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (py/requirements-test.txt lists it)")
    env = dict(os.environ, MYPY_CACHE_DIR=str(tmp_path / "mypy_cache"))
    r = subprocess.run([sys.executable, "-m", "mypy.stubtest", "wscg", "--mypy-config-file",
                        str(CONFIG)],
                       capture_output=True, text=True, cwd=tmp_path, env=env)
    assert r.returncode == 0, "stubs that disagree with the modules:\n" + r.stdout + r.stderr
