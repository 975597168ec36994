"""Where numba keeps its compiled kernels when the package's own folder is read-only.

numba caches a compiled kernel (``cache=True``) in the ``__pycache__`` folder beside its
source, or else in the user's ``~/.cache/numba``. A package installed by root (a system
or container image, a cluster's shared environment) and run by a user whose home is not
writable either (a batch account, ``nobody``) has neither, and numba refuses to compile:
``cannot cache function ...: no locator available``.

:func:`configure` runs once when the package is imported, before any kernel is compiled.
If ``NUMBA_CACHE_DIR`` is set, numba uses it and nothing is done. If the kernels'
``__pycache__`` folders are writable, numba keeps its cache there and nothing is done.
Otherwise ``NUMBA_CACHE_DIR`` is set to the first writable per-user folder of:

1. ``$XDG_CACHE_HOME/uq/numba`` (when ``XDG_CACHE_HOME`` is an absolute path);
2. ``~/.cache/uq/numba`` (the platform's user cache folder on Linux);
3. ``<temporary folder>/uq-numba-<uid>``, created owner-only (0700) and used only if it
   is a folder (not a link) owned by the user;
4. where that name is taken by something else (a link another user planted, a folder
   they own), a new owner-only folder for this process alone
   (``<temporary folder>/uq-numba-<uid>-XXXXXXXX``, removed at exit: the kernels are
   compiled again by the next run), said in :data:`NOTES`.

Where no folder is writable at all, numba refuses to compile ("no locator available"),
which the command line reports in one line.

The cache changes how fast a kernel loads, never what it computes. Only the standard
library is imported (``import uq`` stays light).
"""
import atexit
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

#: The environment variable numba reads for its cache folder.
CACHE_VARIABLE = "NUMBA_CACHE_DIR"
#: Sub-packages whose modules hold ``cache=True`` kernels (their ``__pycache__`` folders
#: are numba's first choice).
KERNEL_PACKAGES = ("engine", "physics")
#: Owner-only permissions of the shared temporary fallback folder.
PRIVATE_MODE = 0o700
#: What :func:`configure` had to settle for, in words (the command line warns of each).
NOTES = []


def configure(environ=None, package=None):
    """Point numba at a writable cache folder when the package's own is read-only.

    Parameters
    ----------
    environ : mapping, optional
        The environment to read and update (default :data:`os.environ`).
    package : path-like, optional
        The package folder whose kernel folders are checked (default: this package).

    Returns
    -------
    str or None
        The folder set in ``NUMBA_CACHE_DIR`` (or already set there), None when numba
        keeps its cache beside the code (or no folder is writable: numba then reports
        it).
    """
    environ = os.environ if environ is None else environ
    if environ.get(CACHE_VARIABLE):
        return environ[CACHE_VARIABLE]
    package = Path(__file__).parent if package is None else Path(package)
    if all(writable(package / name / "__pycache__") for name in KERNEL_PACKAGES):
        return None
    for folder in user_folders(environ):
        if writable(folder):
            environ[CACHE_VARIABLE] = str(folder)
            _tell_numba(str(folder))
            return str(folder)
    return None


def user_folders(environ):
    """The per-user candidates for the cache folder, first choice first."""
    folders = []
    xdg = environ.get("XDG_CACHE_HOME", "")
    if os.path.isabs(xdg):
        folders.append(Path(xdg) / "uq" / "numba")
    home = environ.get("HOME") or os.path.expanduser("~")
    if os.path.isabs(home):
        folders.append(Path(home) / ".cache" / "uq" / "numba")
    private = _private_temporary()
    return folders + ([private] if private is not None else [])


def writable(folder):
    """Can files be created in `folder` (created if missing)? Tested by creating one,
    as numba does (permission bits do not tell for root, ACLs or read-only mounts)."""
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _private_temporary():
    """``<tmp>/uq-numba-<uid>``, made owner-only; None if it cannot be made, or someone
    else owns it, or it is not a plain folder (a link planted in a shared folder)."""
    folder = Path(tempfile.gettempdir()) / f"uq-numba-{os.getuid()}"
    try:
        folder.mkdir(mode=PRIVATE_MODE, exist_ok=True)
        info = os.lstat(folder)
    except OSError:
        return None
    if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
        return _process_folder(folder)
    return folder


def _process_folder(taken):
    """A new owner-only folder beside `taken` (a name someone else holds) for this
    process alone, removed at exit; None if none can be made. Said in :data:`NOTES`."""
    try:
        folder = tempfile.mkdtemp(prefix=f"{taken.name}-", dir=taken.parent)
    except OSError:
        return None
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    NOTES.append(f"{taken} is not a folder of this user (a link, or another user's): "
                 f"numba's compiled kernels are kept in {folder} for this run only (compiled "
                 "again next time); set NUMBA_CACHE_DIR to a folder of yours to keep them")
    return Path(folder)


def _tell_numba(folder):
    """numba reads the variable when it is imported; if it already was, set its config."""
    config = sys.modules.get("numba.core.config")
    if config is not None:
        config.CACHE_DIR = folder
