"""Benchmarks for meshmark: ``python -m bench --faces N --out FILE`` (not installed)."""
