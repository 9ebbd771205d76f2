#!/usr/bin/env python3
"""Builds the `wscg` wheel that a cluster can install (README, "Wheels"): one abi3 wheel for
CPython 3.9 and later, tagged manylinux2014 (glibc 2.17), with the `wscg` command-line
program inside it.

1. `cargo rustc -p wscg-cli --bin wscg -- -C linker=<zig>` links the program with zig (the
   `ziglang` package from PyPI, through `maturin zig cc`) against glibc 2.17 and copies it
   to py/python/wscg/_bin/wscg, where the wheel's `wscg` entry point (wscg._cli) finds it;
2. `maturin build --compatibility manylinux2014 -- -C linker=<zig>` builds the extension
   module with the same linker (`maturin build --zig` does the same but for an explicit
   `--target`, a separate cargo build folder compiled from scratch) and packs both into
   the wheel. The linker is given to the final crates only, so the dependencies are those
   that `cargo build` and `maturin develop` compiled in the same CARGO_TARGET_DIR;
3. `auditwheel show` (when installed) reports the wheel's platform tag.

Usage: python3 scripts/build_wheel.py [--release] [--out DIR]. Needs maturin and ziglang
(`pip install maturin ziglang`) in the running Python; CARGO_TARGET_DIR is honoured.
"""

from __future__ import annotations

import argparse
import glob
import os
import pathlib
import shlex
import shutil
import stat
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
# manylinux2014 = glibc 2.17, the oldest glibc that Rust's standard library supports.
GLIBC = "2.17"
POLICY = "manylinux2014"


def _zig_linker(folder: pathlib.Path) -> pathlib.Path:
    """A linker for cargo: maturin's zig wrapper (`maturin zig cc`, which adapts rustc's
    linker arguments to zig) for x86_64/aarch64 Linux with glibc 2.17, written into
    `folder` (the build folder: a fixed path, so the final crates' rustc flags, and with
    them cargo's fingerprints, stay the same from one build to the next)."""
    arch = os.uname().machine
    target = {"x86_64": "x86_64", "aarch64": "aarch64", "arm64": "aarch64"}.get(arch)
    if target is None:
        raise SystemExit(f"build_wheel: no zig target for the machine {arch!r}")
    script = folder / "wscg-zigcc"
    # maturin finds zig through `python -m ziglang` of the Python on PATH.
    bindir = os.path.dirname(sys.executable)
    script.write_text(
        "#!/bin/sh\n"
        f"PATH={shlex.quote(bindir)}:$PATH exec {shlex.quote(sys.executable)} -m maturin zig cc "
        f"-- -target {target}-linux-gnu.{GLIBC} \"$@\"\n")
    script.chmod(script.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return script


def build(release: bool, out: pathlib.Path) -> pathlib.Path:
    """Builds the wheel into ``out`` and returns its path."""
    target_dir = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")).resolve()
    profile = "release" if release else "debug"
    out.mkdir(parents=True, exist_ok=True)
    before = set(glob.glob(str(out / "*.whl")))
    env = dict(os.environ)
    # zig links the two final artifacts only (`-C linker=` on the final crate's rustc
    # command line): every dependency is the one `cargo build` and `maturin develop`
    # compiled. A linker set for the whole target (CARGO_TARGET_<triple>_LINKER) would
    # change the fingerprint of every crate and compile the workspace twice more.
    target_dir.mkdir(parents=True, exist_ok=True)
    linker = ["-C", f"linker={_zig_linker(target_dir)}"]
    t0 = time.perf_counter()
    cmd = (["cargo", "rustc", "-p", "wscg-cli", "--bin", "wscg"]
           + (["--release"] if release else []) + ["--"] + linker)
    subprocess.run(cmd, cwd=ROOT, env=env, check=True)
    print(f"build_wheel: wscg-cli built in {time.perf_counter() - t0:.0f} s")
    exe = "wscg.exe" if os.name == "nt" else "wscg"
    bundled = ROOT / "py" / "python" / "wscg" / "_bin"
    bundled.mkdir(exist_ok=True)
    # Without its debug information (a debug build's program is ~150 MiB with it).
    if shutil.which("strip"):
        subprocess.run(["strip", "-o", str(bundled / exe), str(target_dir / profile / exe)],
                       check=True)
    else:
        shutil.copy2(target_dir / profile / exe, bundled / exe)
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "maturin", "build", "--manifest-path",
           str(ROOT / "py" / "Cargo.toml"), "--compatibility", POLICY, "--out",
           str(out)] + (["--release"] if release else []) + ["--"] + linker
    subprocess.run(cmd, cwd=ROOT, env=env, check=True)
    print(f"build_wheel: wheel built in {time.perf_counter() - t0:.0f} s")
    wheels = sorted(set(glob.glob(str(out / "*.whl"))) - before) or sorted(
        glob.glob(str(out / "*.whl")), key=os.path.getmtime)[-1:]
    wheel = pathlib.Path(wheels[-1])
    if _has_module("auditwheel"):
        subprocess.run([sys.executable, "-m", "auditwheel", "show", str(wheel)], check=False)
    print(wheel)
    return wheel


def _has_module(name: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(name) is not None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--release", action="store_true", help="optimised build (slower)")
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "dist",
                    help="folder for the wheel (default: dist/)")
    args = ap.parse_args()
    build(args.release, args.out)


if __name__ == "__main__":
    main()
