"""Wing: benchmarks (``uq bench``; ``python -m uq.bench.sweep``)."""
