"""flex: when may a link of a deployment mechanism be modelled as rigid?

A study workspace for flexible multibody dynamics (Exudyn rigid and FFRF bodies, NGsolve
meshes, HDF5 results), reproducing and extending A. Cavezza's 2012 thesis on a spring-driven
slider-crank deployment mechanism. The README is the guide; ``docs/`` holds the findings.

The names a script or notebook needs (contracts in :mod:`flex.api`)::

    from flex import load_scene, derive_scene, simulate, run_study, open_result

- :func:`load_scene` -- read a scene (TOML file or bundled ``cavezza2012``), validated
- :func:`derive_scene` -- a new scene with ``section.key`` overrides (list or dict)
- :func:`simulate` -- simulate one scene in memory (``auto`` links decided first)
- :func:`run_study` -- run a study as ``flex run`` does (HDF5 file, figures, report)
- :func:`open_result` -- one case of a result file as an ``xarray.Dataset``
- :class:`FlexError` -- what every problem a user can fix raises (one-line message)

``import flex`` is light: these names are loaded on first use (no Exudyn or NGsolve until a
simulation needs them).
"""

__version__ = "0.1.0"

#: public name -> module that defines it (loaded on first access, see ``__getattr__``)
_PUBLIC = {
    "load_scene": "flex.api",
    "derive_scene": "flex.api",
    "simulate": "flex.api",
    "run_study": "flex.api",
    "open_result": "flex.api",
    "FlexError": "flex.base.errors",
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str):
    """Load a public name on first access (PEP 562), so ``import flex`` stays light and the
    library's modules can import ``flex`` without a cycle."""
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'flex' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PUBLIC))
