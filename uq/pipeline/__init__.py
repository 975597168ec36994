"""Scenario file -> sweep -> Dataset: validation, planning, the runner."""
