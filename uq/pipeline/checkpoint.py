"""Checkpoints of a long sweep on disk, so an interrupted run can be resumed. No physics.

Each finished chunk of scenes is written to ``<output>.partial/chunk-<index>.nc``
(atomically: temporary file, then rename) with a SHA-256 checksum beside it
(``chunk-<index>.nc.sha256``), and ``manifest.json`` records what the chunks belong to:
the scenario text, the seed, the uq version, the chunk plan (every chunk's group and
scenes) and the SHA-256 of every file the scenario reads (a motion record,
:func:`uq.pipeline.motionsection.input_files`), with a digest of all of that that each
chunk also carries. ``--resume`` reuses the chunks whose checksum and digest match and
recomputes the rest (a chunk that fails is named in a warning); netCDF stores float64
exactly, so the resumed result is bit for bit the uninterrupted one. A resume after such
a file was edited is refused, naming the file (its chunks would mix the old content
with the new); so is a chunk whose file changed while the run was going.

A checkpoint has one owner: the run holds an exclusive lock (``flock`` on
``<output>.partial/lock``, released by the operating system even after ``kill -9``); a
second run on the same output is refused. The folder carries the marker of
:mod:`uq.files`; a folder of that name that uq did not write is never used or removed.
Once the results file is written, the folder is removed (only the files uq put there).
"""
import contextlib
import fcntl
import hashlib
import json
import logging
import os
import re
import stat as stat_module
from pathlib import Path

from uq._version import __version__
from uq.errors import CheckpointError, DataFileError, OutputError
from uq.files import (MARKER, netcdf_bytes, write_bytes, write_marker, write_netcdf, write_text,
                      written_by_uq)

MANIFEST = "manifest.json"
LOCK = "lock"
DIGEST_ATTRIBUTE = "checkpoint_digest"
_CHUNK = re.compile(r"chunk-(\d{6})\.nc")
log = logging.getLogger(__name__)


def checkpoint_directory(output):
    """Where the checkpoints of results file `output` live."""
    output = Path(output)
    return output.with_name(output.name + ".partial")


class Checkpoint:
    """Finished chunks of one run (see the module docstring).

    Parameters
    ----------
    directory : str or pathlib.Path
    resume : bool
        Reuse what a previous run of the same scenario left; otherwise start afresh.
    notify : callable, optional
        Called with one line of text: what a resumed run reused (:meth:`resumed`).
    """

    def __init__(self, directory, resume=False, notify=None):
        self.directory = Path(directory)
        self.resume = resume
        self.notify = notify
        self.digest = None
        self.inputs = ()
        self._lock = None
        self.seed = self._previous().get("seed") if resume else None

    # --- ownership ---------------------------------------------------------------
    def acquire(self):
        """Create (or adopt) the folder and take its lock; CheckpointError if another
        run holds it or uq did not write it."""
        self._claim_folder()
        handle = os.open(self.directory / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            owner = os.read(handle, 64).decode(errors="replace").strip() or "?"
            os.close(handle)
            raise CheckpointError(str(self.directory), "", f"in use by another run (process "
                                  f"{owner}); allowed: one run per output at a time (wait "
                                  "for it, or write elsewhere with -o)") from None
        os.ftruncate(handle, 0)
        os.write(handle, str(os.getpid()).encode())
        self._lock = handle
        if self.resume:
            self.seed = self._previous().get("seed")
        return self

    @contextlib.contextmanager
    def held(self):
        """Hold the lock for a block (taken here unless the caller already holds it)."""
        taken = self._lock is None
        if taken:
            self.acquire()
        try:
            yield self
        finally:
            if taken:
                self.release()

    def __del__(self):
        self.release()

    def release(self):
        """Let go of the lock (the folder stays for --resume)."""
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None

    def _claim_folder(self):
        folder = self.directory
        try:
            folder.mkdir(parents=True)
            write_marker(folder, "checkpoint")
            return
        except FileExistsError:
            pass
        except OSError as error:
            raise OutputError(str(folder), "", f"cannot create the checkpoint folder "
                              f"({error.strerror}); allowed: a writable place") from None
        contents = {p.name for p in folder.iterdir()} if folder.is_dir() else None
        if contents is None or not (written_by_uq(folder) or contents <= {LOCK}):
            raise CheckpointError(str(folder), "", "exists and was not written by uq; "
                                  "allowed: remove or rename it yourself, or write the "
                                  "results elsewhere with -o")
        if MARKER not in contents:
            write_marker(folder, "checkpoint")

    # --- the run -----------------------------------------------------------------
    def _previous(self):
        try:
            return json.loads((self.directory / MANIFEST).read_text())
        except (OSError, ValueError):
            return {}

    def start(self, scenario, seed, chunks, model="compiled"):
        """Check (resume) or write (fresh) the manifest of this run; `chunks` is the
        sweep plan's chunks (index, group, start, stop); `model` the measurement model
        (``uq run --model``: a run never mixes the chunks of two models)."""
        from uq.pipeline.motionsection import input_files
        plan = [[c.index, list(c.group), c.start, c.stop] for c in chunks]
        self.inputs = tuple(InputFile.of(key, path) for key, path in input_files(scenario))
        manifest = {"scenario": scenario.text, "seed": int(seed), "uq_version": __version__,
                    "chunks": len(plan), "plan": plan,
                    "files": [[f.key, f.path, f.sha256] for f in self.inputs],
                    **({"model": model} if model != "compiled" else {})}
        text = json.dumps(manifest, sort_keys=True)
        self.digest = hashlib.sha256(text.encode()).hexdigest()
        manifest["digest"] = self.digest
        if self.resume and (self.directory / MANIFEST).exists():
            previous = self._previous()
            if previous != manifest:
                self._refuse_changed_files(previous, manifest)
                raise CheckpointError(str(self.directory), MANIFEST, "the checkpoint belongs "
                                      "to a different scenario, seed, chunk plan, model "
                                      "(--model) or uq version; allowed: resume the same run, or run without "
                                      "--resume to start afresh")
            return
        self._remove_chunks()                 # a fresh start: the folder is ours (marked)
        self._remove(self.directory / MANIFEST)
        write_text(self.directory / MANIFEST, json.dumps(manifest, indent=1),
                   checkpoint=True)

    def _refuse_changed_files(self, previous, manifest):
        """CheckpointError naming a file the scenario reads whose content differs from
        the one the checkpoint was made with (the rest of the manifest being the same)."""
        rest = {k: v for k, v in manifest.items() if k not in ("files", "digest")}
        if {k: v for k, v in previous.items() if k not in ("files", "digest")} != rest:
            return
        before = {(key, path): digest for key, path, digest in previous.get("files", [])}
        for key, path, digest in manifest["files"]:
            if before.get((key, path)) != digest:
                raise CheckpointError(path, key, f"changed since the checkpoint "
                                      f"{self.directory} was written (its SHA-256 differs); "
                                      "allowed: restore the file to resume, or run without "
                                      "--resume to start afresh")

    def load(self):
        """Chunk index -> Dataset of every intact chunk of this run on disk; a chunk that
        fails its checksum or belongs to another run is removed and recomputed."""
        from uq.pipeline.results import read_results
        chunks = {}
        for path in sorted(self.directory.glob("chunk-*.nc")):
            match = _CHUNK.fullmatch(path.name)
            problem = "bad name" if not match else self._verify(path)
            dataset = None
            if not problem:
                try:
                    dataset = read_results(path)
                except (OSError, ValueError, RuntimeError):
                    problem = "unreadable"
            if dataset is not None and dataset.attrs.get(DIGEST_ATTRIBUTE) != self.digest:
                problem, dataset = "written by another run", None
            if problem:
                log.warning("checkpoint chunk %s: %s; it is recomputed", path, problem)
                self._remove(path)
                self._remove(path.with_name(path.name + ".sha256"))
                continue
            chunks[int(match.group(1))] = dataset
        return chunks

    def resumed(self, reused, total):
        """Say (through `notify`, a callable of one line of text) how many of a resumed
        run's `total` chunks were `reused` from the folder and how many remain."""
        if not (self.resume and self.notify):
            return
        if reused:
            self.notify(f"resuming from {self.directory}: {reused} of {total} chunks reused, "
                        f"{total - reused} to compute")
        else:
            self.notify(f"--resume: no finished chunk in {self.directory}; all {total} "
                        "chunks to compute")

    def _verify(self, path):
        """'' if the chunk's bytes match its recorded SHA-256, else what is wrong."""
        try:
            recorded = path.with_name(path.name + ".sha256").read_text().strip()
        except OSError:
            return "no checksum"
        return "" if _sha256(path) == recorded else "checksum mismatch"

    def save(self, index, dataset, encoded=None):
        """Keep a finished chunk (after checking that no file the scenario reads has
        changed since the run started: DataFileError naming it). `encoded`: its file
        as :func:`encode_chunk` made it with this run's digest (on a dask worker),
        written as it is; else the chunk's file is written here."""
        for item in self.inputs:
            item.verify()
        path = self.directory / f"chunk-{index:06d}.nc"
        if encoded is None:
            write_netcdf(_with_digest(dataset, self.digest), path, checkpoint=True)
            digest = _sha256(path)
        else:
            write_bytes(path, encoded, checkpoint=True)
            digest = hashlib.sha256(encoded).hexdigest()
        write_text(path.with_name(path.name + ".sha256"), digest + "\n", checkpoint=True)

    def is_empty(self):
        """No chunk on disk (nothing a --resume could reuse)?"""
        return not any(self.directory.glob("chunk-*.nc"))

    def clear(self):
        """Remove the checkpoint (the files uq wrote there, then the folder if empty)."""
        self._remove_chunks()
        for name in (MANIFEST, MARKER, LOCK):
            self._remove(self.directory / name)
        self.release()
        try:
            self.directory.rmdir()
        except OSError:
            if self.directory.exists():
                log.warning("checkpoint folder %s kept: it holds files uq did not write",
                            self.directory)

    def _remove_chunks(self):
        for path in self.directory.glob("chunk-*.nc*"):
            if _CHUNK.fullmatch(path.name.removesuffix(".sha256")):
                self._remove(path)

    @staticmethod
    def _remove(path):
        try:
            path.unlink()
        except FileNotFoundError:
            pass


def encode_chunk(dataset, digest):
    """The checkpoint file of a finished chunk, as bytes: its netCDF4 file
    (:func:`uq.files.netcdf_bytes`) carrying the run's `digest`. Pure: a dask worker
    makes it beside the chunk, so the run's own process only writes it to disk."""
    return netcdf_bytes(_with_digest(dataset, digest))


def _with_digest(dataset, digest):
    """A shallow copy of a chunk's `dataset` carrying the run's `digest`."""
    dataset = dataset.copy(deep=False)
    dataset.attrs[DIGEST_ATTRIBUTE] = digest
    return dataset


class InputFile:
    """A file a scenario reads, with its SHA-256 when the run started, and the size and
    modification time it then had (a file whose size and time are unchanged is not read
    again to check it)."""

    def __init__(self, key, path, sha256, stat):
        self.key, self.path, self.sha256, self._stat = key, path, sha256, stat

    @classmethod
    def of(cls, key, path):
        stat = _stat(path, key)
        return cls(key, path, _sha256(path, key), stat)

    def verify(self):
        """DataFileError if the content changed since :meth:`of`."""
        stat = _stat(self.path, self.key)
        if stat == self._stat:
            return
        if _sha256(self.path, self.key) != self.sha256:
            raise DataFileError(self.path, self.key, "changed while the run was going (its "
                                "SHA-256 differs from the one at the start); the chunks "
                                "finished before are kept; allowed: leave the files a run "
                                "reads alone until it ends, restore the file and run again "
                                "with --resume, or run without --resume")
        self._stat = stat


def _stat(path, key):
    try:
        stat = os.stat(path)
    except OSError as error:
        raise DataFileError(str(path), key, f"cannot read it ({error.strerror}); allowed: "
                            "the file the scenario names") from None
    return stat.st_size, stat.st_mtime_ns


def _sha256(path, key=None):
    digest = hashlib.sha256()
    try:
        handle = os.open(path, os.O_RDONLY | os.O_NONBLOCK)    # a FIFO: no wait for a writer
    except OSError as error:
        if key is None:
            raise
        raise DataFileError(str(path), key, f"cannot read it ({error.strerror}); allowed: "
                            "the file the scenario names") from None
    with open(handle, "rb") as stream:
        if key is not None and not stat_module.S_ISREG(os.fstat(handle).st_mode):
            raise DataFileError(str(path), key, "not a regular file; allowed: a file")
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
