"""Benchmarks: speed and memory targets, measured against named peers in the same run."""
