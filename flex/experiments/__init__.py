"""What the studies compute: fits, work-precision, benchmark, stability, per-study tables and
figures.
"""
