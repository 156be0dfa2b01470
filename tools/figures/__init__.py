"""Numbers, tables and plots for the docs, numpy only (README.md)."""
