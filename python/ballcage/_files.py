"""Writing output files atomically: a reader sees the previous file or the complete new one, never a part."""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pyarrow as pa
    from matplotlib.figure import Figure

__all__ = ["write_atomically", "write_parquet", "write_png", "write_text"]


def write_atomically(final: Path, write: Callable[[Path], object]) -> None:
    """Writes `final` through a hidden temporary file in the same directory.

    `write(tmp)` fills the temporary file; it is then fsynced and renamed over
    `final` (``os.replace``, atomic on POSIX and Windows). On any exception the
    temporary file is removed and `final` is left as it was.
    """
    tmp = final.with_name(f".{final.name}.{secrets.token_hex(4)}.tmp")
    # O_EXCL: never clobber another writer's temporary; mode 0o666 minus umask,
    # the permissions a plain open() would give the final file.
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    try:
        write(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, final)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_directory(final.parent)


def write_parquet(table: pa.Table, path: Path) -> Path:
    """Writes `table` to `path` as zstd-compressed Parquet, atomically; returns `path`."""
    import pyarrow.parquet as pq  # deferred: only writers pay for it

    write_atomically(path, lambda tmp: pq.write_table(table, str(tmp), compression="zstd"))
    return path


def write_png(figure: Figure, path: Path, dpi: int = 120) -> Path:
    """Renders `figure` to `path` as PNG at `dpi` dots per inch, atomically; returns `path`."""
    write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=dpi))
    return path


def write_text(text: str, path: Path) -> Path:
    """Writes `text` to `path` as UTF-8, atomically; returns `path`."""
    write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return path


def _fsync_directory(directory: Path) -> None:
    """Makes a rename durable; a no-op where directories cannot be opened (Windows)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
