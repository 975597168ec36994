"""``python -m uq.cli``: the same as the ``uq`` command."""
import sys

from uq.cli import main

sys.exit(main())
