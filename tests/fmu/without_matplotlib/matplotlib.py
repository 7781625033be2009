"""Stands in for matplotlib on the PYTHONPATH of the ballistic-limit
script's runs (test_ballistic_limit.py), so that they write their plot with
the script's own SVG writer, which those tests check element by element,
although the venv has matplotlib (for the Python package's walk-through)."""

raise ImportError("matplotlib is hidden from this run by tests/fmu/without_matplotlib")
