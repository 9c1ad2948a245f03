"""Writing output files atomically: a reader sees the previous file or the complete new one, never a part."""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pyarrow as pa
    from matplotlib.figure import Figure

__all__ = ["parquet_writer", "write_all_atomically", "write_atomically", "write_parquet", "write_png", "write_text"]


def write_atomically(final: Path, write: Callable[[Path], object]) -> None:
    """Writes `final` through a hidden temporary file in the same directory.

    `write(tmp)` fills the temporary file; it is then fsynced and renamed over
    `final` (``os.replace``, atomic on POSIX and Windows). On any exception the
    temporary file is removed and `final` is left as it was. The temporary is
    ``.<name>.<8 hex digits>.tmp``: a process killed mid-write (SIGKILL, power
    loss) may leave it behind, hidden and never under a final name (pyarrow's
    dataset discovery skips names starting with a dot). A failed write raises
    `OSError` naming `final` and the reason (e.g. ``[Errno 28] No space left on
    device: '<final>'``), not the temporary's name.
    """
    write_all_atomically({final: write})


def write_all_atomically(files: Mapping[Path, Callable[[Path], object]]) -> None:
    """Writes several files so that a failure changes none of them: every temporary first, then the renames.

    Each ``write(tmp)`` of `files` (final path -> writer) fills its own hidden
    temporary (as `write_atomically`), which is fsynced; only when all are
    written are they renamed over their final names, one after the other. A
    write that fails (a full disk, Ctrl-C) removes every temporary and leaves
    each final file as it was, so an output folder never mixes two runs'
    files; only a process killed within the renames themselves (microseconds)
    can leave some renamed and not others.
    """
    temporaries: list[tuple[Path, Path]] = []
    try:
        for final, write in files.items():
            # Listed before it exists, so that a Ctrl-C landing between its creation and the listing cannot leave
            # it behind (the clean-up tolerates a name never created); unlisted again only if the name was taken.
            tmp = final.with_name(f".{final.name}.{secrets.token_hex(4)}.tmp")
            temporaries.append((tmp, final))
            try:
                _create_temporary(tmp, final)
            except FileExistsError:
                temporaries.pop()  # another writer's temporary: not ours to remove
                raise
            _fill(tmp, final, write)
        for tmp, final in temporaries:
            os.replace(tmp, final)
    except BaseException:
        for tmp, _ in temporaries:
            tmp.unlink(missing_ok=True)
        raise
    for directory in dict.fromkeys(final.parent for final in files):
        _fsync_directory(directory)


def _create_temporary(tmp: Path, final: Path) -> None:
    """Creates the empty hidden temporary `tmp` (``.<name>.<8 hex digits>.tmp`` beside `final`)."""
    try:
        # O_EXCL: never clobber another writer's temporary; mode 0o666 minus umask,
        # the permissions a plain open() would give the final file.
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except OSError as e:
        raise _naming(e, tmp, final) or e


def _fill(tmp: Path, final: Path, write: Callable[[Path], object]) -> None:
    """Runs ``write(tmp)`` and fsyncs `tmp`; an `OSError` is raised naming `final` (see `_naming`)."""
    try:
        write(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as e:
        raise _naming(e, tmp, final) or e


def _naming(error: OSError, tmp: Path, final: Path) -> OSError | None:
    """`error`'s errno naming `final` instead of `tmp` (or of no file); ``None`` when `error` names another file.

    pyarrow's messages ("Error writing bytes to file. Detail: [errno 28] ...")
    name no file; the errno's own text ("No space left on device") is the reason a reader needs.
    The result's ``__cause__`` is `error`.
    """
    if error.filename is not None and os.fspath(error.filename) != os.fspath(tmp):
        return None
    reason = os.strerror(error.errno) if error.errno else (error.strerror or str(error))
    named = OSError(error.errno, reason, str(final))
    named.__cause__ = error
    return named


def parquet_writer(table: pa.Table) -> Callable[[Path], None]:
    """The one Parquet writer (zstd-compressed) of `table`: fills the path it is given, for `write_atomically`."""

    def write(tmp: Path) -> None:
        import pyarrow.parquet as pq  # deferred: only writers pay for it

        pq.write_table(table, str(tmp), compression="zstd")

    return write


def write_parquet(table: pa.Table, path: Path) -> Path:
    """Writes `table` to `path` as zstd-compressed Parquet (`parquet_writer`), atomically; returns `path`."""
    write_atomically(path, parquet_writer(table))
    return path


def png_writer(figure: Figure, dpi: int = 120) -> Callable[[Path], None]:
    """The one PNG writer of `figure` at `dpi` dots per inch: fills the path it is given, for `write_atomically`."""

    def write(tmp: Path) -> None:
        figure.savefig(tmp, format="png", dpi=dpi)

    return write


def write_with_figure(
    key: str, table: pa.Table, figure: Figure, out: Path, files: tuple[str, str]
) -> dict[str, Path]:
    """Writes `table` (Parquet) and `figure` (PNG) into `out` as `files`, both or neither (a run killed while writing
    them leaves no table without its figure); returns their paths as ``key`` and ``<key>_figure``."""
    paths = {key: out / files[0], f"{key}_figure": out / files[1]}
    write_all_atomically({paths[key]: parquet_writer(table), paths[f"{key}_figure"]: png_writer(figure)})
    return paths


def write_png(figure: Figure, path: Path, dpi: int = 120) -> Path:
    """Renders `figure` to `path` as PNG at `dpi` dots per inch (`png_writer`), atomically; returns `path`."""
    write_atomically(path, png_writer(figure, dpi))
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
