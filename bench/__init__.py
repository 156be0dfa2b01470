"""Benchmarks (not tests): ``python -m bench`` prints figures; ratios are measured in the same run."""
