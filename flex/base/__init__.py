"""Foundations: errors and exit statuses, closed forms, the thesis's numbers, closed-form
kinematics, figure helpers (numpy, math, matplotlib only).
"""
