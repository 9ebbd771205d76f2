"""The ``wscg`` command of the wheel: runs the command-line program bundled in the package
(``wscg/_bin/wscg``, the ``wscg-cli`` crate's binary), with the same arguments, exit status
and standard streams. A package built with ``maturin develop`` bundles no binary; there the
command says how to get one (``cargo install --path crates/cli``)."""

from __future__ import annotations

import os
import subprocess
import sys
from typing import List, Optional

__all__ = ["main", "binary"]


def binary() -> Optional[str]:
    """The path of the bundled ``wscg`` program, or None when this installation has none."""
    name = "wscg.exe" if os.name == "nt" else "wscg"
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_bin", name)
    return path if os.path.isfile(path) else None


def main(argv: Optional[List[str]] = None) -> int:
    """Runs the bundled program with ``argv`` (default: this process's arguments) and
    returns its exit status; on POSIX the program replaces this process."""
    args = sys.argv[1:] if argv is None else list(argv)
    exe = binary()
    if exe is None:
        sys.stderr.write(
            "wscg: this installation of the Python package has no bundled command-line "
            "program (a development build); install a wheel built by scripts/build_wheel.py, "
            "or the program itself with `cargo install --path crates/cli`\n")
        return 2
    if argv is None and os.name == "posix":
        sys.stdout.flush()
        sys.stderr.flush()
        os.execv(exe, [exe, *args])
    return subprocess.call([exe, *args])


if __name__ == "__main__":
    sys.exit(main())
