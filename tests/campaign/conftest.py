"""Fixtures of the campaign's tests."""
import pytest


@pytest.fixture
def coarse_tables(monkeypatch):
    """Tables of few nodes (for the plumbing: their error is measured and large): the
    spectral path at 2 speeds x 3 directions, the motion's curvature every 0.2 Hz (the
    motion's response and noise keep their nine directions: exact in direction)."""
    from uq.campaign import surrogate
    monkeypatch.setattr(surrogate, "SPEED_NODES", 2)
    monkeypatch.setattr(surrogate, "SPECTRAL_DIRECTIONS", 3)
    monkeypatch.setattr(surrogate, "CURVATURE_STEP", 0.2)
