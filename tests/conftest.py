import os

os.environ.setdefault("EXUDYN_NO_USER_SETTINGS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")
