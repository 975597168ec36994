"""Reading an input file without hanging or exhausting memory: regular files only, opened
without blocking, bounded in bytes and rows before anything is parsed. No physics.

Every file the tool reads (scenario, motion record, fit configuration and table, golden
configuration and tables) comes through here. Whatever sits at the path costs at most one
``fstat`` and `limit` bytes:

* what is not a regular file is refused unread, saying what it is: a folder, a named
  pipe (a FIFO with no writer would block ``open`` forever: the file is opened with
  ``O_NONBLOCK`` and the kind is read from the open descriptor), a device such as
  ``/dev/zero`` (endless), a socket; a symbolic link is judged by what it points to;
* a file larger than its limit is refused from its size, unread (a 2 GB sparse file costs
  nothing);
* a table with more rows than its limit is refused before it is parsed.

Each problem is one :class:`~uq.errors.InputError` (of the caller's class) naming the
file, the key that named it and the kind of input that was expected (``a CSV motion
record``, not ``a YAML file``).
"""
import io
import os
import stat

from uq.errors import ScenarioError

#: What an ``fstat`` mode is, for the message, when it is not a regular file.
_NOT_REGULAR = ((stat.S_ISDIR, "is a folder"),
                (stat.S_ISFIFO, "is a named pipe (FIFO), not a regular file"),
                (stat.S_ISCHR, "is a character device (such as /dev/zero), not a regular file"),
                (stat.S_ISBLK, "is a block device, not a regular file"),
                (stat.S_ISSOCK, "is a socket, not a regular file"))


def size_text(limit):
    """`limit` [bytes] as people read it: KiB up to 1 MiB, MiB above."""
    return f"{limit // 1024} KiB" if limit <= 1 << 20 else f"{limit / (1 << 20):g} MiB"


def read_bytes(path, limit, kind, error=ScenarioError, key=""):
    """The bytes of the regular file at `path`, at most `limit` [bytes].

    Parameters
    ----------
    path : path-like
        The file.
    limit : int
        Largest size allowed [bytes].
    kind : str
        What the file should be, for messages (``"a CSV motion record"``).
    error : type
        The :class:`~uq.errors.InputError` subclass raised.
    key : str
        The key that named the file (``"motion.series.file"``), or ``""``.
    """
    allowed = f"allowed: {kind} of at most {size_text(limit)}"
    try:
        handle = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as problem:
        raise error(str(path), key, f"cannot read the file ({problem.strerror or problem}); "
                    f"allowed: {kind}") from None
    try:
        info = os.fstat(handle)
        _refuse_irregular(info.st_mode, path, key, allowed, error)
        if info.st_size > limit:
            raise error(str(path), key, f"{info.st_size} bytes, larger than "
                        f"{size_text(limit)}; {allowed}")
        data = _read_at_most(handle, limit + 1)
    except OSError as problem:
        raise error(str(path), key, f"cannot read the file ({problem.strerror or problem}); "
                    f"allowed: {kind}") from None
    finally:
        os.close(handle)
    if len(data) > limit:                        # it grew while being read
        raise error(str(path), key, f"larger than {size_text(limit)}; {allowed}")
    return data


def check_regular(path, limit, kind, error=ScenarioError, key=""):
    """Refuse `path` unless it is a regular file of at most `limit` bytes (for a file a
    library opens itself, such as netCDF); returns its size [bytes]."""
    allowed = f"allowed: {kind} of at most {size_text(limit)}"
    try:
        info = os.stat(path)
    except OSError as problem:
        raise error(str(path), key, f"cannot read the file ({problem.strerror or problem}); "
                    f"allowed: {kind}") from None
    _refuse_irregular(info.st_mode, path, key, allowed, error)
    if info.st_size > limit:
        raise error(str(path), key, f"{info.st_size} bytes, larger than {size_text(limit)}; "
                    f"{allowed}")
    return info.st_size


def _refuse_irregular(mode, path, key, allowed, error):
    if stat.S_ISREG(mode):
        return
    what = next((text for test, text in _NOT_REGULAR if test(mode)), "is not a regular file")
    raise error(str(path), key, f"{what}; {allowed}")


def _read_at_most(handle, count):
    chunks, left = [], count
    while left > 0:
        chunk = os.read(handle, min(left, 1 << 20))
        if not chunk:
            break
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def decode(data, source, error=ScenarioError, key=""):
    """UTF-8 text of `data` (a byte-order mark is allowed), or `error` naming `source`."""
    if b"\x00" in data:
        raise error(source, key, "holds NUL bytes (binary data or UTF-16 text); allowed: "
                    "UTF-8 text")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as problem:
        line = data[:problem.start].count(b"\n") + 1
        raise error(source, key, f"not UTF-8 text (byte {data[problem.start]:#04x} at line "
                    f"{line}; Latin-1 or another encoding?); allowed: UTF-8 text") from None


def read_csv(path, limit, max_rows, kind, error, key=""):
    """The CSV table at `path` (pandas DataFrame, first line the header), refused unparsed
    if it is larger than `limit` bytes or has more than `max_rows` rows of data."""
    import pandas as pd
    text = decode(read_bytes(path, limit, kind, error, key), str(path), error, key)
    rows = text.count("\n") + (not text.endswith("\n")) - 1
    if rows > max_rows:
        raise error(str(path), key, f"{rows} rows; allowed: {kind} of at most {max_rows} "
                    "rows")
    try:
        return pd.read_csv(io.StringIO(text))
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError) as problem:
        reason = str(problem).splitlines()[0][:120] if str(problem) else type(problem).__name__
        raise error(str(path), key, f"cannot read it as CSV ({reason}); allowed: {kind} "
                    "(UTF-8 text, a header row, one row per line)") from None
