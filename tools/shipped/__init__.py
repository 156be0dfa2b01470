"""Building the shipped reference sets and their data (README.md)."""
