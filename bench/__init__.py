"""Benchmarks of ipfric against references run side by side (``./ipfric bench``)."""
