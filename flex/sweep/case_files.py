"""A sweep's case files: one result file per case, the identity of a case (:func:`case_hash`)
and the digest of what its file holds, proved when a rerun resumes it."""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from flex.base.errors import FlexError, ResultFileError
from flex.data.cache import content_digest
from flex.data.results import CaseResult, Dataset, open_results, write_results
from flex.data.scene import Scene, to_toml

#: keyword arguments of a case function that say where things are kept, not what a case
#: computes: left out of its identity (:func:`case_hash`), so a moved cache resumes (a
#: reference store's content enters it as the function's bound store digest)
LOCATION_ARGUMENTS = frozenset({"cache_dir", "reference_store"})
#: 2: a content digest of the case (``sweep_content_digest``), checked when a rerun resumes
SWEEP_FORMAT = "flex-sweep-case/2"


def _physics_versions() -> str:
    """What a flexible link's physics and outputs depend on beyond the scene: the
    reduction's basis (chord frame since version 2), its geometric stiffness, what its
    headline channel reads and where an exact beam's Newton stops (a changed body, channel or
    solver must not resume stale cases)."""
    from flex.base.channel import CHANNEL_FORMAT_VERSION
    from flex.bodies.geometric_stiffness import GEOMETRIC_FORMAT_VERSION
    from flex.bodies.reduction import CACHE_FORMAT_VERSION
    from flex.dynamics.exact_beam_link import EXACT_BEAM_INCREMENT_FRACTION

    return (f"#reduction{CACHE_FORMAT_VERSION}#geometric{GEOMETRIC_FORMAT_VERSION}"
            f"#channel{CHANNEL_FORMAT_VERSION}#beam-increment{EXACT_BEAM_INCREMENT_FRACTION:g}")


def case_hash(scene: Scene, case_function: Callable[..., Any]) -> str:
    """Identity of a case: its resolved scene and the case function's qualified name and
    ``case_version`` attribute (bumped when what the function stores changes: stale case
    files are then rerun, not resumed), and, for a scene with ``"auto"`` values, what they
    resolve from: the calibration's digest (:attr:`flex.config.calibration.Calibration.digest`:
    the fitted laws, the FFRF rule and the solver defaults as one; the case function's bound
    ``calibration``, else the bundled one) and the load prediction's margin."""
    from flex.config import settings
    from flex.config.calibration import calibration_of
    from flex.fidelity.auto import has_auto_models
    from flex.fidelity.laws import criteria_in_force_text

    function, extra, calibration = case_function, "", None
    if isinstance(function, functools.partial):  # bound arguments are part of the identity,
        calibration = function.keywords.get("calibration")
        keywords = sorted((key, value) for key, value in function.keywords.items()
                          if key not in LOCATION_ARGUMENTS  # but not where caches live
                          and key != "calibration")  # (its digest below)
        if function.args or keywords:
            extra = repr((function.args, keywords))
        function = function.func
    if settings.has_auto(scene) or settings.has_auto_link_keys(scene) or has_auto_models(scene):
        # a changed law, rule or table must not resume stale cases
        extra += f"#calibration{calibration_of(calibration).digest}"
    extra += criteria_in_force_text(scene)
    version = getattr(function, "case_version", None)
    if version is not None:
        extra += f"@{version}"
    extra += _physics_versions()
    label = f"{function.__module__}.{function.__qualname__}{extra}"
    return hashlib.sha256((label + "\n" + to_toml(scene)).encode()).hexdigest()[:24]


def case_path(folder: str | Path, name: str) -> Path:
    """``<folder>/cases/<name>.h5``."""
    return Path(folder) / "cases" / f"{name}.h5"


def write_case_file(folder: str | Path, case: CaseResult, digest: str, study: str) -> Path:
    """Write one case to its own file, atomically (the hash of what it ran and the digest of
    what it holds, :func:`case_content_digest`, go in the root attributes)."""
    return write_results(case_path(folder, case.name), study, [case], case.scene_toml,
                         attrs={"sweep_case_hash": digest, "sweep_format": SWEEP_FORMAT,
                                "sweep_content_digest": case_content_digest(case)})


def case_content_digest(case: CaseResult) -> str:
    """Digest of everything a case file holds (:func:`flex.data.cache.content_digest`):
    status, message, scenes, counters, attributes, and every dataset's values, units and
    description; the same for a case and for the case read back from its file."""
    parts: list[tuple[str, Any]] = [("name", case.name), ("status", case.status),
                                    ("message", case.message), ("scene", case.scene_toml),
                                    ("solver", case.solver_settings_toml)]
    parts += [(f"counter:{key}", case.counters[key]) for key in sorted(case.counters)]
    parts += [(f"attr:{key}", case.attrs[key]) for key in sorted(case.attrs)]
    for name in sorted(case.datasets):
        dataset = case.datasets[name]
        parts += [(f"data:{name}", dataset.data), (f"units:{name}", dataset.units),
                  (f"description:{name}", dataset.description)]
    return content_digest(parts)


def _text(value: Any) -> Any:
    return value.decode() if isinstance(value, bytes) else value


def read_case_file(path: str | Path) -> tuple[CaseResult, str]:
    """The :class:`CaseResult` stored in a case file and its case hash.

    Raises :class:`flex.base.errors.ResultFileError` for a missing or damaged file.
    """
    import h5py

    with open_results(path) as h5:
        digest = str(_text(h5.attrs.get("sweep_case_hash", "")))
        content = str(_text(h5.attrs.get("sweep_content_digest", "")))
        names = list(h5["cases"])
        if len(names) != 1:
            raise FlexError(f"case file '{path}' holds {len(names)} cases, expected 1")
        group = h5["cases"][names[0]]
        attrs = {k: _text(v) for k, v in group.attrs.items()}
        datasets: dict[str, Dataset] = {}

        def visit(name: str, obj: Any) -> None:
            if isinstance(obj, h5py.Dataset):
                value = obj[()]
                if isinstance(value, bytes):
                    value = value.decode()
                datasets[name] = Dataset(value, str(_text(obj.attrs.get("units", ""))),
                                         str(_text(obj.attrs.get("description", ""))))

        group.visititems(visit)
    counters = {k[len("counter_"):]: v for k, v in attrs.items() if k.startswith("counter_")}
    fixed = ("status", "message", "scene_toml", "solver_settings_toml")
    extra = {k: v for k, v in attrs.items() if k not in fixed and not k.startswith("counter_")}
    case = CaseResult(names[0], str(attrs.get("scene_toml", "")), datasets,
                      status=str(attrs.get("status", "failed")),
                      message=str(attrs.get("message", "")), counters=counters,
                      solver_settings_toml=str(attrs.get("solver_settings_toml", "")),
                      attrs=extra)
    if content != case_content_digest(case):
        raise ResultFileError(f"case file '{path}' did not prove its content (its content "
                              f"digest does not match: damaged, edited or of an older format)")
    return case, digest

