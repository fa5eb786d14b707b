import os

import pytest

os.environ.setdefault("EXUDYN_NO_USER_SETTINGS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def reduction_cache():
    """The reduction cache folder of in-process runs: the user's, as ``flex run`` finds it
    (``FLEX_CACHE_DIR``, ``XDG_CACHE_HOME``, ``~/.cache``), so FFRF tests load their reductions
    instead of meshing them again. The tests are an edge: they read the environment here."""
    from flex.bodies.reduction import reduction_cache_dir

    return reduction_cache_dir(os.environ)
