"""Sphinx configuration of the uq user guide.

Build it (warnings are errors, as in CI)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The command-line, scenario and performance references are generated while the guide
builds (``docs/_ext/uqdocs.py``); the notebooks of ``notebooks/`` are executed against the
installed package and rendered (MyST-NB). Nothing is fetched from the network.
"""
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import uq  # noqa: E402  (the installed package: the guide documents what is installed)

project = "uq"
author = "the uq developers"
copyright = "the uq developers, MIT licence"
release = uq.__version__
version = release

extensions = [
    "myst_nb",                 # Markdown pages (MyST) and executed notebooks
    "sphinx.ext.autodoc",      # the API reference from the docstrings
    "numpydoc",                # ... written in numpydoc style
    "sphinx.ext.mathjax",      # formulas (MathJax is loaded by the reader's browser)
    "uqdocs",                  # generated pages (CLI, scenario keys, performance)
]

source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build", "scenario.md", "README.md", "**.ipynb_checkpoints",
                    "data/*"]

# MyST: $...$ maths, ::: fences, anchors for headings (links to #sections resolve)
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# notebooks: executed each build, in a temporary folder (they write nothing), a failing
# cell fails the build
nb_execution_mode = os.environ.get("UQ_DOCS_EXECUTE", "force")
nb_execution_in_temp = True
nb_execution_raise_on_error = True
nb_execution_timeout = 600
nb_merge_streams = True

# numpydoc: sections as written; no autosummary tables of members
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
autodoc_default_options = {"members": True, "undoc-members": False}
autodoc_member_order = "bysource"

# every cross-reference must resolve (warnings are errors in CI)
nitpicky = False
# a numpydoc References list need not be cited in the text above it
suppress_warnings = ["myst.xref_ambiguous", "ref.citation"]

html_theme = "alabaster"
html_title = f"uq {release}"
html_static_path = []
html_theme_options = {"description": "Uncertainty of ship-based and floating Doppler "
                      "wind lidar", "fixed_sidebar": True}

# the performance page reads this uq bench result (docs/data/ is committed; point the
# guide at another file with UQ_BENCH_FILE=path)
uq_bench_file = os.environ.get("UQ_BENCH_FILE", str(HERE / "data" / "bench.nc"))
