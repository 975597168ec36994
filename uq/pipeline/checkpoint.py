"""Checkpoints of a long sweep on disk, so an interrupted run can be resumed. No physics.

Each finished chunk of scenes is written to ``<output>.partial/chunk-<index>.nc``
(atomically: temporary file, then rename), beside a ``manifest.json`` that records what
the chunks belong to: the scenario text, the seed, the number of chunks and the uq
version. ``--resume`` reuses the chunks of a matching manifest and computes the rest;
netCDF stores float64 exactly, so the resumed result is bit for bit the uninterrupted
one. The directory is removed once the results file is written.
"""
import json
import shutil
from pathlib import Path

from uq._version import __version__
from uq.errors import CheckpointError
from uq.files import write_netcdf, write_text
from uq.pipeline.results import read_results

MANIFEST = "manifest.json"


def checkpoint_directory(output):
    """Where the checkpoints of results file `output` live."""
    output = Path(output)
    return output.with_name(output.name + ".partial")


class Checkpoint:
    """Finished chunks of one run.

    Parameters
    ----------
    directory : str or pathlib.Path
    resume : bool
        Reuse what a previous run of the same scenario left; otherwise start afresh.
    """

    def __init__(self, directory, resume=False):
        self.directory = Path(directory)
        self.resume = resume
        self.seed = self._previous().get("seed") if resume else None

    def _previous(self):
        try:
            return json.loads((self.directory / MANIFEST).read_text())
        except (OSError, ValueError):
            return {}

    def start(self, scenario, seed, n_chunks):
        """Check (resume) or write (fresh) the manifest of this run."""
        manifest = {"scenario": scenario.text, "seed": int(seed), "chunks": n_chunks,
                    "uq_version": __version__}
        if self.resume and self.directory.exists():
            previous = self._previous()
            if previous != manifest:
                raise CheckpointError(str(self.directory), MANIFEST, "the checkpoint belongs to a "
                                    "different scenario, seed or uq version; allowed: resume "
                                    "the same run, or run without --resume to start afresh")
            return
        self.clear()
        self.directory.mkdir(parents=True)
        write_text(self.directory / MANIFEST, json.dumps(manifest, indent=1))

    def load(self):
        """Chunk index -> Dataset of every chunk on disk."""
        return {int(path.stem.split("-")[1]): read_results(path)
                for path in sorted(self.directory.glob("chunk-*.nc"))}

    def save(self, index, dataset):
        write_netcdf(dataset, self.directory / f"chunk-{index:06d}.nc")

    def clear(self):
        shutil.rmtree(self.directory, ignore_errors=True)

