"""Dev-only helpers shared by tests, benchmarks and tools (not shipped in the extension zip)."""
