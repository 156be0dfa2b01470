"""The test matrix (``python3 -m tools.matrix``): lanes.py holds the lanes and runs them."""
