"""Scenes and result files: TOML scenes and their schema, HDF5 files with units and provenance,
where outputs go.
"""
