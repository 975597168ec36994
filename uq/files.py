"""Writing files without losing anyone's data: the one place where uq writes to disk.

Rules (DEVELOPERS.md, "Never lose a user's data"):

* **Atomic.** Every file is written to a temporary name beside its target and renamed
  into place (:func:`atomic_file`); a failure or an interruption leaves the earlier file,
  or nothing, never half a file. The temporary file is removed on failure.
* **Ordinary permissions.** The new file gets the permissions any other new file would
  get, ``0o666 & ~umask`` (0644 under umask 022), not the owner-only 0600 of
  :func:`tempfile.mkstemp`.
* **Only its own.** The tool replaces only what it wrote itself: a file it wrote carries
  a signature (:func:`written_by_uq`: the ``uq_version`` attribute of a netCDF file, the
  text :data:`SIGNATURE` in a report, a figure's metadata), a folder it wrote holds the
  marker file :data:`MARKER`. Anything else at a target is refused with an
  :class:`~uq.errors.OutputError`, never removed.
* **Names are names.** An output name taken from a configuration (``golden.name``) is a
  file name, never a path (:func:`check_name`).
* **Folders are swapped whole.** A folder of outputs is written complete under a
  temporary name and renamed into place (:func:`replace_folder`); an earlier folder of
  the tool's own is renamed aside first and removed only after the new one is in place.

No physics, no numbers; numpy-free, so the command line can import it cheaply.
"""
import contextlib
import json
import os
import re
import shutil
import signal
import tempfile
import threading
from pathlib import Path

from uq._version import __version__
from uq.errors import OutputError
from uq.interrupts import exception_for, raise_if_stopped, stop

#: Text that marks a file as written by uq (in reports and figure metadata).
SIGNATURE = "written by uq"
#: Name of the marker file inside every folder uq creates.
MARKER = ".uq-output"
#: Bytes read from each end of a file when looking for :data:`SIGNATURE`.
_SIGNATURE_WINDOW = 1 << 16
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
#: How the netCDF library's errors begin (a RuntimeError): a write that fails with one is a
#: failed write (a full disk: "NetCDF: HDF error"), not a bug.
NETCDF_ERROR = "NetCDF:"
#: Free space [bytes] below which a failed write is reported as a full file system: less
#: than one chunk of results (~50 KiB to a few MiB).
FULL_DISK_BYTES = 4 << 20


def file_mode():
    """Permission bits of a new file under the process's umask (``0o666 & ~umask``)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def folder_mode():
    """Permission bits of a new folder under the process's umask (``0o777 & ~umask``)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o777 & ~mask


def check_name(name, source, key):
    """`name` if it is a plain file name (letters, digits, ``_ . -``; not starting with
    a dot, so never ``.``, ``..`` or hidden), else OutputError naming `source` and `key`."""
    if not isinstance(name, str) or not _NAME.fullmatch(name) or len(name) > 200:
        raise OutputError(source, key, f"{name!r} is not allowed; allowed: a file name of "
                          "letters, digits, '_', '.', '-' (not a path, not empty, not "
                          "starting with '.', at most 200 characters)")
    return name


def written_by_uq(path):
    """Did uq write the file or folder at `path`? (See the module docstring.)"""
    path = Path(path)
    if path.is_dir():
        return (path / MARKER).is_file()
    if not path.is_file():
        return False
    if path.suffix == ".nc":
        return _netcdf_written_by_uq(path)
    return _has_signature(path)


def _netcdf_written_by_uq(path):
    try:
        import netCDF4
        with netCDF4.Dataset(path) as handle:
            return "uq_version" in handle.ncattrs()
    except (OSError, RuntimeError, ValueError):
        return False


def _has_signature(path):
    try:
        with open(path, "rb") as stream:
            head = stream.read(_SIGNATURE_WINDOW)
            stream.seek(max(0, path.stat().st_size - _SIGNATURE_WINDOW))
            tail = stream.read()
    except OSError:
        return False
    signature = SIGNATURE.encode()
    return signature in head or signature in tail


def missing_folders(folder):
    """The folders of `folder`'s path that do not exist yet, deepest first (those a
    write would create, and :func:`remove_if_empty` may remove again)."""
    folder, missing = Path(folder).absolute(), []
    while not folder.exists() and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    return missing


def remove_if_empty(folders):
    """Remove each folder (deepest first) that exists and is empty."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


def _not_a_folder(path, source):
    """`path`, or OutputError where it is a folder."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(source, str(path), "is a folder; allowed: a file name")
    return path


def check_target(path, source="-o"):
    """Refuse a target the tool may not write: a folder, or a file it did not write."""
    path = _not_a_folder(path, source)
    if path.exists() and not written_by_uq(path):
        raise OutputError(source, str(path), "exists and was not written by uq; allowed: "
                          "a new file name (uq replaces only its own files)")
    return path


@contextlib.contextmanager
def atomic_file(path, source="-o", replace_any=False, *, checkpoint=False):
    """Yield a temporary path beside `path`; on success give it the umask's permissions
    and rename it onto `path`, on failure remove it. Refuses targets uq did not write,
    unless the user asked to replace any file (`replace_any`, ``uq export --force``);
    a folder is refused always. A result is not put in place while a Ctrl-C is pending
    (:func:`uq.interrupts.raise_if_stopped`), unless it is a `checkpoint` file (a
    finished chunk, kept for ``--resume``)."""
    path = check_target(path, source) if not replace_any else _not_a_folder(path, source)
    _make_folder(path.parent, source)
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                             dir=path.parent)
    except OSError as error:
        raise OutputError(source, str(path), f"cannot write in {path.parent} "
                          f"({error.strerror}); allowed: a writable folder") from None
    os.close(handle)
    try:
        with deferred_interrupt():           # Ctrl-C waits until the file is whole
            yield Path(temporary)
            os.chmod(temporary, file_mode())
            if not checkpoint:
                raise_if_stopped()           # a Ctrl-C lost on its way: no result
            os.replace(temporary, path)
    except (OSError, RuntimeError) as error:     # a full disk, a quota, a read-only mount
        if isinstance(error, RuntimeError) and not str(error).startswith(NETCDF_ERROR):
            Path(temporary).unlink(missing_ok=True)
            raise
        reason = (getattr(error, "strerror", None) or str(error)) + _full_disk(path.parent)
        Path(temporary).unlink(missing_ok=True)
        raise OutputError(source, str(path), f"cannot write it ({reason}); nothing was "
                          "written; allowed: a folder with space and write permission"
                          ) from None
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def deferred_interrupt():
    """Hold Ctrl-C (SIGINT) and SIGTERM back until the block is done, then raise
    KeyboardInterrupt (:class:`~uq.errors.Terminated` for SIGTERM); under the command
    line's handler also pending until handled (:func:`uq.interrupts.stop`), never in a
    library call (nothing is pending outside the command line).

    A KeyboardInterrupt in the middle of a netCDF write can leave the writer's internal
    (non-reentrant) lock held, and its clean-up then waits on it forever; a write takes
    milliseconds, so the interrupt is taken at its end. Only in the main thread (the only
    one that receives signals); elsewhere the block runs as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received = []
    previous = {number: signal.signal(number, lambda got, frame: received.append(got))
                for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    if received:                             # SIGTERM first
        number = signal.SIGTERM if signal.SIGTERM in received else signal.SIGINT
        if previous[number] is stop:         # the command line's: written down, watched
            stop(number)
        raise exception_for(number)          # elsewhere (a library call) only raised


def _full_disk(folder):
    """'; the file system is full (N KiB free)' when it has less than FULL_DISK_BYTES
    free for the user, else ''. The netCDF library reports a full disk as 'NetCDF: HDF
    error' (HDF5 loses the errno); the free space tells what it was."""
    try:
        info = os.statvfs(folder)
    except OSError:
        return ""
    free = info.f_bavail * info.f_frsize
    return f"; the file system is full ({free // 1024} KiB free)" if free < FULL_DISK_BYTES \
        else ""


def _make_folder(folder, source):
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(source, str(folder), f"cannot create the folder "
                          f"({error.strerror}); allowed: a writable folder") from None


def write_text(path, text, source="-o", replace_any=False, *, checkpoint=False):
    """Write `text` to `path` atomically; returns the path. `replace_any`: replace a file
    uq did not write (only where the user asked for it); `checkpoint`: see
    :func:`atomic_file`."""
    with atomic_file(path, source, replace_any, checkpoint=checkpoint) as temporary:
        temporary.write_text(text)
    return Path(path)


def write_bytes(path, data, source="-o", *, checkpoint=False):
    """Write the bytes `data` to `path` atomically; returns the path (`checkpoint`: see
    :func:`atomic_file`)."""
    with atomic_file(path, source, checkpoint=checkpoint) as temporary:
        temporary.write_bytes(data)
    return Path(path)


def write_netcdf(dataset, path, source="-o", *, checkpoint=False):
    """Write an xarray Dataset to netCDF4 at `path` atomically, stamped with
    ``uq_version`` (its mark of ownership); returns the path (`checkpoint`: see
    :func:`atomic_file`)."""
    with atomic_file(path, source, checkpoint=checkpoint) as temporary:
        _stamped(dataset).to_netcdf(temporary, format="NETCDF4", engine="netcdf4")
    return Path(path)


def netcdf_bytes(dataset):
    """The netCDF4 file :func:`write_netcdf` writes, as bytes made in memory (a dask
    worker encodes a checkpoint chunk so; the run's own process only writes them)."""
    return bytes(_stamped(dataset).to_netcdf(format="NETCDF4", engine="netcdf4"))


def _stamped(dataset):
    """`dataset` with ``uq_version`` among its attributes (a shallow copy if it lacks it)."""
    if "uq_version" in dataset.attrs:
        return dataset
    dataset = dataset.copy(deep=False)
    dataset.attrs["uq_version"] = __version__
    return dataset


def save_figure(figure, path, source="-o", **options):
    """Save a matplotlib figure atomically, its metadata signed (:data:`SIGNATURE`)."""
    path = Path(path)
    extension = path.suffix.lstrip(".")
    key = {"png": "Software", "pdf": "Creator", "svg": "Creator"}.get(extension)
    metadata = {key: f"uq {__version__} ({SIGNATURE})"} if key else None
    with atomic_file(path, source) as temporary:
        figure.savefig(temporary, format=extension, metadata=metadata, **options)
    return path


def output_folder(folder, source="-o"):
    """Create `folder` if needed and return it. Files are added to it one by one, each
    refused if it would replace a file uq did not write (:func:`atomic_file`)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise OutputError(source, str(folder), "exists and is not a folder; allowed: a "
                          "folder name")
    _make_folder(folder, source)
    return folder


def write_marker(folder, kind):
    """Mark `folder` as created by uq (the :data:`MARKER` file)."""
    marker = Path(folder) / MARKER
    marker.write_text(json.dumps({"written_by": "uq", "uq_version": __version__,
                                  "kind": kind}) + "\n")
    os.chmod(marker, file_mode())


def new_partial_folder(folder, source="-o"):
    """A fresh, empty temporary folder beside `folder` for :func:`replace_folder`."""
    folder = Path(folder)
    _make_folder(folder.parent, source)
    partial = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", suffix=".partial",
                                    dir=folder.parent))
    os.chmod(partial, folder_mode())
    return partial


def check_folder_target(folder, source="-o"):
    """Refuse a folder target that :func:`replace_folder` would refuse: a file, a link,
    or a non-empty folder uq did not write."""
    folder = Path(folder)
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise OutputError(source, str(folder), "exists and is not a folder uq wrote; "
                          "allowed: a new folder name")
    if folder.is_dir() and any(folder.iterdir()) and not written_by_uq(folder):
        raise OutputError(source, str(folder), "exists and was not written by uq; allowed: "
                          "a new folder name, an empty folder, or a folder uq wrote (uq "
                          "replaces only its own outputs)")
    return folder


def replace_folder(partial, folder, kind, source="-o"):
    """Put the complete folder `partial` in place of `folder`.

    `folder` may be absent, empty, or an earlier output of the tool (it holds
    :data:`MARKER`); anything else is refused (OutputError) and `partial` removed. The
    earlier folder is renamed aside, the new one renamed into place, and only then is
    the earlier one (the tool's own) deleted.
    """
    partial, folder = Path(partial), Path(folder)
    try:
        raise_if_stopped()                   # a Ctrl-C lost on its way: no result
    except KeyboardInterrupt:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    write_marker(partial, kind)
    aside = None
    if folder.exists() or folder.is_symlink():
        try:
            check_folder_target(folder, source)
        except OutputError:
            shutil.rmtree(partial, ignore_errors=True)
            raise
        aside = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", suffix=".old",
                                      dir=folder.parent))
        os.replace(folder, aside / folder.name)
    os.replace(partial, folder)
    if aside is not None:
        shutil.rmtree(aside, ignore_errors=True)
    return folder
