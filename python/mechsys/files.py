"""Writing output files without losing anything: every writer (results, CSV, plots) writes a
temporary file beside its target, flushes it to disk and renames it over the target, so a
failure or an interrupt part-way leaves the previous file as it was; and the command line checks
its output paths before it simulates (not an input of the same command, not twice the same
file, a directory it can write in), so a bad path costs nothing.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Callable, Iterator

from .errors import SettingsError


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path in ``path``'s directory to write to; on success it replaces ``path``
    (after an fsync), on any failure (also KeyboardInterrupt) it is removed and ``path`` is
    untouched. A symbolic link at ``path`` is replaced, not its target."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=parent, prefix=f".{path.name}.", suffix=".part")
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        with open(tmp_path, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp_path, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise
    with contextlib.suppress(OSError):
        # the rename itself reaches the disk with the directory's entry
        dfd = os.open(parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


def write_atomically(path: str | Path, writer: Callable[[Path], object]) -> Path:
    """Calls ``writer(temporary path)`` and moves the result over ``path`` (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


def _same(a: Path, b: Path) -> bool:
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        pass
    return a.resolve() == b.resolve()


def check_outputs(inputs: dict[str, Path], outputs: dict[str, Path | None], follow_symlinks: bool = False) -> dict:
    """Refuses, before any work, an output that is one of the command's inputs (``--out
    model.toml``), one file named by two outputs, a directory, a symbolic link (unless
    ``follow_symlinks``: then its target is written), or a place that cannot be written; the
    messages name the option. ``inputs``/``outputs`` map option names to paths. Returns the
    outputs to write (links resolved when followed)."""
    given = {k: Path(v) for k, v in outputs.items() if v is not None}
    for opt, out in list(given.items()):
        if out.is_symlink():
            if not follow_symlinks:
                raise SettingsError(f"{opt} {out}: is a symbolic link (to {os.readlink(out)}); refused, since writing "
                                    "through it would replace another file (--follow-symlinks writes its target)")
            given[opt] = out = out.resolve()
        for what, inp in inputs.items():
            if _same(out, Path(inp)):
                raise SettingsError(f"{opt} {out}: that is the {what}; writing there would replace it (choose another file)")
        if out.is_dir():
            raise SettingsError(f"{opt} {out}: is a directory (give a file name)")
        parent = out.parent if str(out.parent) else Path(".")
        probe = parent
        while not probe.exists() and probe != probe.parent:
            probe = probe.parent
        if not probe.is_dir():
            raise SettingsError(f"{opt} {out}: {probe} is not a directory")
        if not os.access(probe, os.W_OK | os.X_OK):
            raise SettingsError(f"{opt} {out}: cannot write in {probe} (permission denied)")
    names = list(given)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if _same(given[a], given[b]):
                raise SettingsError(f"{a} and {b} name the same file {given[a]}; each output needs its own")
    return {k: given.get(k) for k in outputs}


__all__ = ["atomic_path", "write_atomically", "check_outputs"]
