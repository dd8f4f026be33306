"""Publishing results: files appear whole or not at all, nothing that is not ours is clobbered,
and JSON holds only what JSON can.

Where a result goes decides how it is written (:func:`publish`):

- a new file, or an existing regular file: written to a temporary file beside it and renamed
  over it (linked, when nothing is there), so a reader never sees half a file; an existing file
  keeps its permissions;
- never over a results file of this program or a file another process holds locked (a running
  batch): those are looked at again just before the rename, under a shared lock held across it
  (:func:`rrtpso_ompl.ownership.inspected`), and refused with an ``OutputError``;
- a symbolic link: written through to its target (by the rules for the target), the link stays;
- a fifo, a character device or ``-`` (standard output): streamed directly, since renaming over
  them would replace the fifo (its reader would get nothing) or the device node.

Everything that writes a file goes through :func:`atomic_path` (for writers that need a file
name: matplotlib, SQLite) or :func:`write_text_atomic`; a writer that makes a folder of its own
(a ROS 2 bag) writes inside :func:`atomic_folder`, which renames the finished folder into place
(over nothing, or an empty folder: a folder with anything in it is never replaced); files that
belong together (a generated problem and its map) are written by :func:`atomic_files`, all or
nothing.

A write that fails (the disk is full, the pipe or standard output is closed, the name is too
long) raises one :class:`~rrtpso_ompl.errors.OutputError` naming the output and the reason, after
the temporary file is removed: the old file stays as it was, and nothing half-written or empty
is left behind. The temporary name is shortened to fit the file system's name limit, so any name
that may be written may also be written atomically.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import shutil
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .errors import OutputError
from .ownership import ABSENT, MOVED, inspected

__all__ = [
    "STDOUT",
    "atomic_files",
    "atomic_folder",
    "atomic_path",
    "finite",
    "guard_standard_streams",
    "is_stream",
    "json_line",
    "link_new",
    "make_folders",
    "name_max",
    "os_reason",
    "publish",
    "remove_folders",
    "results_only_on_stdout",
    "silence_stdout",
    "stdout_closed",
    "write_json_atomic",
    "write_stdout",
    "write_text_atomic",
]

#: The output name that means standard output.
STDOUT = "-"
#: Longest file name when the file system does not say (NAME_MAX of Linux, macOS, Windows), bytes.
DEFAULT_NAME_MAX = 255
#: Characters of randomness ``tempfile.mkstemp`` puts in a name.
_RANDOM_CHARS = 8

_stdout_closed = False
#: The file descriptor Python's standard output writes to: 1, or its duplicate while
#: :func:`results_only_on_stdout` holds descriptor 1 for standard error.
_stdout_fd = 1


def guard_standard_streams() -> None:
    """Make a closed standard input, output or error harmless (``rrtpso ... >&-``).

    A closed descriptor 0, 1 or 2 is pointed at the null device, so that no file this process
    opens later takes its number (OMPL's messages to standard output would land in a results
    file). A closed standard output is remembered: writing to it (``--json -``) is then refused
    (:func:`stdout_closed`). A closed standard error becomes the null device, so messages are
    dropped instead of falling through to standard output.
    """
    global _stdout_closed
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_RDWR)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
            if fd == 1:
                _stdout_closed = True
                sys.stdout = None  # type: ignore[assignment]
            elif fd == 2:
                sys.stderr = open(fd, "w", closefd=False)  # noqa: SIM115 - for the process
    if sys.stdout is None:
        _stdout_closed = True


@contextmanager
def results_only_on_stdout() -> Iterator[None]:
    """Keep standard output for results while the block runs: file descriptor 1 (where OMPL's
    C++ code writes its Info and Debug lines, and any library's ``printf``) goes to standard
    error, and Python's ``sys.stdout`` writes to the real standard output through a duplicate
    of it.

    So ``rrtpso solve -v --json -`` and ``rrtpso batch -v --out -`` write nothing but their
    results on standard output, whatever OMPL's log level, and every log line goes to standard
    error. Processes started meanwhile (the workers of a batch) inherit descriptor 1 as it is
    then, standard error: the duplicate is not inherited, so no worker can write there.
    Everything is put back when the block ends (a caller such as a test runs commands in its
    own process).
    """
    global _stdout_fd
    with contextlib.suppress(AttributeError, ValueError, OSError):
        sys.stdout.flush()  # what was written before goes where it was meant to
    saved = os.dup(1)  # not inheritable (PEP 446)
    _flush_c_stdio()
    os.dup2(2, 1)
    old, new = sys.stdout, None
    if old is not None and _writes_to_fd(old, 1):
        new = io.TextIOWrapper(
            open(saved, "wb", closefd=True),  # noqa: SIM115 - closed when the block ends
            encoding=old.encoding, errors=old.errors, line_buffering=old.line_buffering,
        )  # fmt: skip
        sys.stdout = new
        _stdout_fd = saved
    try:
        yield
    finally:
        if new is not None:
            with contextlib.suppress(OSError, ValueError):
                new.flush()
        _flush_c_stdio()  # OMPL's lines still buffered by C's stdio go to standard error
        os.dup2(saved, 1)  # also after silence_stdout: then descriptor 1 is the null device
        _stdout_fd = 1
        if new is not None:
            sys.stdout = old
            with contextlib.suppress(OSError, ValueError):
                new.close()  # closes `saved`
        else:
            os.close(saved)


def _writes_to_fd(stream: Any, fd: int) -> bool:
    """Whether the text stream ``stream`` writes to file descriptor ``fd``."""
    try:
        return stream.fileno() == fd
    except (AttributeError, ValueError, OSError):  # a test's capture, a closed stream
        return False


def _flush_c_stdio() -> None:
    """Flush C's stdio buffers (``fflush(NULL)``), where C++'s ``std::cout`` may hold lines."""
    import ctypes

    with contextlib.suppress(OSError, AttributeError, TypeError):
        ctypes.CDLL(None).fflush(None)


def stdout_closed() -> bool:
    """Whether the process was started with standard output closed (nothing can go there)."""
    return _stdout_closed or sys.stdout is None


def os_reason(exc: BaseException) -> str:
    """Why an OS call failed, in the system's words (``No space left on device``)."""
    if isinstance(exc, OutputError):
        return exc.reason
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


def write_stdout(text: str) -> None:
    """Write ``text`` to standard output and flush it; OutputError when that fails (but a reader
    that went away raises BrokenPipeError: the command line stops quietly then)."""
    if stdout_closed():
        raise OutputError(STDOUT, "it is closed")
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        raise OutputError(STDOUT, os_reason(exc)) from None


def silence_stdout() -> None:
    """Point standard output at /dev/null once its reader went away (a closed pipe).

    What is still buffered or written later is dropped instead of raising BrokenPipeError again,
    also in Python's own flush at exit (the way Python's documentation of SIGPIPE advises).
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, _stdout_fd)
    finally:
        os.close(devnull)


def name_max(folder: str | Path) -> int:
    """The longest file name (bytes) the file system holding ``folder`` allows."""
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return DEFAULT_NAME_MAX


def is_stream(path: str | Path) -> bool:
    """Whether ``path`` is written as a stream: ``-``, or an existing fifo or character device
    (after following links)."""
    if str(path) == STDOUT:
        return True
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)


def _resolved(path: str | Path) -> Path:
    """``path`` with symbolic links followed (also a dangling link's target)."""
    return Path(os.path.realpath(path))


def publish(tmp: str | Path, path: str | Path) -> None:
    """Move a finished temporary file to ``path`` by the rules of the module docstring."""
    if str(path) == STDOUT:
        if stdout_closed():
            raise OutputError(STDOUT, "it is closed")
        with open(tmp, "rb") as src:
            try:
                sys.stdout.flush()
                shutil.copyfileobj(src, sys.stdout.buffer)
                sys.stdout.buffer.flush()
            except BrokenPipeError:
                # The reader left (`--json - | head -c 100`): its choice, not an error; the
                # command goes on and exits with its own status (0 solved, 1 unsolved).
                silence_stdout()
        Path(tmp).unlink(missing_ok=True)
        return
    target = _resolved(path)
    if is_stream(target):
        with open(tmp, "rb") as src, open(target, "wb") as dst:
            shutil.copyfileobj(src, dst)
        Path(tmp).unlink(missing_ok=True)
        return
    for _ in range(_PUBLISH_ATTEMPTS):
        with inspected(target) as found:
            if found == MOVED:
                continue  # renamed over while we looked: look at the new file
            if found == ABSENT:
                _chmod_new(tmp)
                if link_new(tmp, target):
                    return
                continue  # made meanwhile (by a batch?): look at it
            if found is not None:  # a results file, or one being written: never replaced
                raise OutputError(str(path), f"it is {found.what}; it is left as it is")
            # Held under a shared lock: a batch cannot take the file until it is replaced.
            os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))  # it keeps its permissions
            os.replace(tmp, target)
            return
    raise OutputError(str(path), "other processes keep creating and removing it")


#: Looks at a target that other processes keep creating, replacing or removing.
_PUBLISH_ATTEMPTS = 10


def _chmod_new(tmp: str | Path) -> None:
    """Give ``tmp`` the permissions any new file gets (mkstemp's files are owner-only)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)


def link_new(tmp: str | Path, target: Path) -> bool:
    """Put ``tmp`` at ``target`` only if nothing is there (a hard link, then ``tmp`` removed:
    a rename would replace a file made meanwhile, such as a batch's new results file). False
    when something is there now; a file system without hard links gets a rename."""
    try:
        os.link(tmp, target)
    except FileExistsError:
        return False
    except OSError:  # no hard links here (FAT, some network file systems): rename
        os.replace(tmp, target)
        return True
    with contextlib.suppress(OSError):
        os.unlink(tmp)
    return True


@contextmanager
def atomic_path(path: str | Path, suffix: str | None = None) -> Iterator[str]:
    """A temporary file name to write to; published to ``path`` (:func:`publish`) when the block
    ends without an exception, removed otherwise.

    The temporary file lies beside the (resolved) target, so the final rename is atomic; for a
    stream target it lies in the system's temporary folder. Its name ends in ``suffix`` (default:
    ``path``'s), for writers that choose the format by it (matplotlib, Pillow), and is cut to the
    file system's name limit.

    Raises
    ------
    OutputError
        When the temporary file cannot be made, written or published (an ``OSError`` of the
        block included: the block only writes ``tmp``); ``tmp`` is removed first.
    """
    name = Path(path)
    tmp = None
    made: list[Path] = []
    try:
        if is_stream(path):
            folder = Path(tempfile.gettempdir())
        else:
            folder = _resolved(path).parent
            made = make_folders(folder)
        prefix, end = _temp_affixes(name, suffix, name_max(folder))
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=end, dir=folder)
        os.close(fd)
        yield tmp
        publish(tmp, path)
    except BaseException as exc:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        remove_folders(made)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(str(path), os_reason(exc)) from None
        raise


@contextmanager
def atomic_folder(
    path: str | Path, publish_file: Callable[[Path], Path] | None = None, name: str | None = None
) -> Iterator[Path]:
    """A fresh name to make a folder at, inside a temporary folder beside ``path``'s (resolved)
    target; when the block ends without an exception the folder is moved to ``path``, else
    removed. The temporary folder is removed either way.

    Parameters
    ----------
    path : str or Path
        The target: a new name, or an empty folder (renamed over atomically).
    publish_file : callable, optional
        Given the finished folder, the one file in it to publish to ``path`` instead of the
        folder (by :func:`publish`: an existing regular file is replaced atomically, a link
        written through), for writers that make a folder around the one file wanted (a ROS 2
        bag in one MCAP file).
    name : str, optional
        The name of the folder to make (default: the target's; only with ``publish_file``
        may it differ, since the folder itself is not published then).

    Yields
    ------
    Path
        Where the writer makes its folder (it does not exist yet).

    Raises
    ------
    OutputError
        When the folder cannot be made or published (an ``OSError`` of the block included).
    """
    target = _resolved(path)
    made: list[Path] = []
    scratch = None
    try:
        made = make_folders(target.parent)
        prefix, end = _temp_affixes(Path(target.name), ".tmp", name_max(target.parent))
        scratch = Path(tempfile.mkdtemp(prefix=prefix, suffix=end, dir=target.parent))
        folder = scratch / (name if name and publish_file is not None else target.name)
        yield folder
        if publish_file is not None:
            publish(publish_file(folder), target)
        else:
            os.rename(folder, target)  # atomic; only over nothing or an empty folder
    except BaseException as exc:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
            scratch = None
        remove_folders(made)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(str(path), os_reason(exc)) from None
        raise
    finally:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


@contextmanager
def atomic_files(paths: Sequence[str | Path]) -> Iterator[list[Path]]:
    """Files that appear together or not at all: a temporary name for each of ``paths``, of the
    same name inside one temporary folder beside them (so files that name each other relatively,
    a problem and its map, read each other there); when the block ends without an exception each
    is published (:func:`publish`) in the order given: put the file that names the others last.

    When the block fails, or a file cannot be published, the files already published are
    removed, and so are the temporary folder and the folders made for the files: nothing is left
    behind.

    Parameters
    ----------
    paths : sequence of str or Path
        The targets, all in one folder (not streams: the caller refuses those).

    Yields
    ------
    list of Path
        Where to write each file, in the order of ``paths``.

    Raises
    ------
    OutputError
        When a file cannot be written or published (an ``OSError`` of the block included),
        naming the last of ``paths``.
    """
    targets = [Path(p) for p in paths]
    folder = targets[-1].parent
    if any(t.parent != folder for t in targets):
        raise ValueError(f"atomic_files: the files must lie in one folder, got {targets}")
    made = make_folders(folder) if str(folder) else []
    moved: list[Path] = []
    scratch = None
    try:
        scratch = Path(tempfile.mkdtemp(prefix=f".{targets[-1].name[:40]}.", dir=folder))
        yield [scratch / t.name for t in targets]
        for target in targets:
            publish(scratch / target.name, target)
            moved.append(target)
    except BaseException as exc:
        for p in moved:
            with contextlib.suppress(OSError):
                p.unlink()
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
        remove_folders(made)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(str(targets[-1]), os_reason(exc)) from None
        raise
    shutil.rmtree(scratch, ignore_errors=True)


def make_folders(folder: str | Path) -> list[Path]:
    """Create ``folder`` and its missing parents; the ones created, deepest first (for
    :func:`remove_folders` when what was to go into them could not be written)."""
    made = []
    p = Path(folder)
    while not os.path.lexists(p) and p.parent != p:
        made.append(p)
        p = p.parent
    Path(folder).mkdir(parents=True, exist_ok=True)
    return made


def remove_folders(made: list[Path]) -> None:
    """Remove the folders :func:`make_folders` created, if still empty (nothing empty is left
    behind by a write that failed)."""
    for p in made:
        try:
            os.rmdir(p)
        except OSError:
            return  # not empty (something else was written there) or gone: keep the rest


def _temp_affixes(name: Path, suffix: str | None, limit: int) -> tuple[str, str]:
    """The prefix and suffix of a temporary name for ``name``: ``.<stem>.`` and its suffix, the
    stem cut so that the whole (with mkstemp's random characters) fits in ``limit`` bytes."""
    end = suffix or name.suffix or ".tmp"
    if len(os.fsencode(end)) > limit // 4:  # a suffix that long names no format: drop it
        end = ".tmp"
    room = limit - _RANDOM_CHARS - len(os.fsencode(end)) - 2
    stem = os.fsencode(name.stem or "out")[: max(room, 0)]
    return f".{os.fsdecode(stem)}.", end


def write_text_atomic(text: str, path: str | Path) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) by the rules of :func:`publish`."""
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return Path(path)


def write_json_atomic(data: Any, path: str | Path) -> None:
    """Write JSON (NaN and infinities as null) by the rules of :func:`publish`."""
    text = json.dumps(finite(data), indent=2, allow_nan=False, default=_json_default) + "\n"
    write_text_atomic(text, path)


def json_line(row: Any) -> str:
    """One JSON-lines row: compact, NaN and infinities as null, ending in a newline."""
    return json.dumps(finite(row), allow_nan=False, default=_json_default) + "\n"


def finite(obj: Any) -> Any:
    """The same data with NaN and infinities as None (JSON has neither)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite(v) for v in obj]
    return obj


def _json_default(obj: Any) -> Any:
    # Not imported here: a command that has not loaded numpy holds no numpy object.
    np = sys.modules.get("numpy")
    if np is not None and isinstance(obj, np.ndarray):
        return finite(obj.tolist())
    if np is not None and isinstance(obj, np.generic):
        return finite(obj.item())
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
