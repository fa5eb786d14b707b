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


@pytest.fixture(scope="session")
def tiny_ffrf_file(tmp_path_factory, reduction_cache):
    """A small FFRF result file for the export/animate hostile cases: a coarse 5 mm plate
    coupler (maxh 5 mm, 4 modes, its reduction from the cache), 1 ms, 11 samples; one case
    named ``case``. Tests copy it before changing it."""
    from flex.api import simulate
    from flex.config.settings import pinned_overrides
    from flex.data.results import write_results
    from flex.data.scene import load_scene, to_toml

    scene = load_scene(overrides=[
        *pinned_overrides(), 'coupler.geometry="plate"', "coupler.thickness_m=0.005",
        "coupler.mesh_size_m=0.005", "coupler.modes=4", "simulation.end_time_s=0.001",
        "simulation.output_step_s=1e-4", 'coupler.model="ffrf"',
        "simulation.error_estimate=false"])
    path = tmp_path_factory.mktemp("tiny-ffrf") / "plate.h5"
    return write_results(path, "simulate", [simulate(scene, "case", cache_dir=reduction_cache)],
                         to_toml(scene))
