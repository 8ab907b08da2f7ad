"""Bundled machine-data files (TOML)."""
