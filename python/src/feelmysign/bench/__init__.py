"""Benchmarks printed by ``make bench``: figures, each beside a baseline measured in the same run.

Benchmarks are not tests: nothing here passes or fails on timing.
"""
