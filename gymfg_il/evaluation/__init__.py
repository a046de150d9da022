"""Evaluation: fly agents on the same seeded cases, score them, report tables, JSON and plots."""
