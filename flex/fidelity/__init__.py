"""Rigid or flexible: the criterion, "auto", simulating any scene."""
