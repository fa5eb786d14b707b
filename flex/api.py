"""The public face of flex for scripts and notebooks: five functions with written contracts.

Import them from the package (``from flex import load_scene, simulate``); ``import flex``
itself loads nothing heavy (no Exudyn, NGsolve or h5py until a function needs it)::

    scene = load_scene()                                          # bundled cavezza2012
    soft = derive_scene(scene, {"drive.spring_preload_m": 0.011})  # a derived scene
    case = simulate(soft)                                         # one case, in memory
    out = run_study("simulate", overrides={"drive.spring_preload_m": 0.011},
                    out="runs/soft.h5")                           # a file, as the CLI writes
    ds = open_result("runs/soft.h5")                              # xarray.Dataset

Conventions shared by every function here:

- A **scene** is a nested ``dict`` ``{section: {key: value}}`` whose keys carry their unit
  (``length_m`` [m], ``mass_kg`` [kg], ``inertia_kgm2`` [kg m^2], ``initial_angle_deg``
  [deg], ``spring_stiffness_N_per_m`` [N/m], ``end_time_s`` [s], ``youngs_modulus_Pa``
  [Pa], ...; no suffix: dimensionless or a choice). The accepted keys, types and ranges are
  :data:`flex.data.scene.SCHEMA`; ``python -m flex scene simulate`` prints a full scene.
- **Overrides** are either a list of ``"section.key=value"`` strings (the value in TOML
  syntax, as ``--set`` takes them: ``"coupler.model=ffrf"``, ``"simulation.end_time_s=0.01"``)
  or a ``dict``, flat (``{"drive.spring_preload_m": 0.011}``) or by section
  (``{"drive": {"spring_preload_m": 0.011}}``), with Python values (str, int, float, bool;
  numpy scalars accepted).
- Every problem a user can fix raises a :class:`flex.base.errors.FlexError` subclass whose message
  is one line naming the key or file and the accepted range: :class:`~flex.base.errors.SceneError`
  (a scene or override), :class:`~flex.base.errors.SimulationError` (a run diverged; the message
  names the step and the time), :class:`~flex.base.errors.ResultFileError` (a result file),
  :class:`~flex.base.errors.OutputError` (an output that cannot be written),
  :class:`~flex.base.errors.ArgumentError` (an argument of the wrong type or value, naming
  the argument; also a :class:`TypeError`).
- **The same checks as the command line.** A scene handed to :func:`simulate` or
  :func:`derive_scene` is checked as ``--scene`` and ``--set`` are (a dict edited by hand
  too: ``scene["drive"]["spring_preload_m"] = -0.02`` is refused, ``wing.enabled = "no"``
  is not true), and :func:`simulate` refuses, as ``flex run simulate`` does, a value that
  differs from the bundled scene's but that the scene's models would not read. Numpy
  scalars in a scene are accepted as the numbers they hold. The caller's scene is never
  modified.
- The **reduction cache** (Craig-Bampton reductions of ``ffrf`` plates) is a folder argument,
  ``cache_dir``; left out, these functions read the user's from the environment when called
  (``FLEX_CACHE_DIR``/reductions, else ``$XDG_CACHE_HOME/flex/reductions``, else
  ``~/.cache/flex/reductions``: :func:`flex.bodies.reduction.reduction_cache_dir`), as the
  command line does. The library below takes it as an argument only.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from flex.base.errors import ArgumentError, SceneError

if TYPE_CHECKING:  # type names only; nothing heavy is imported at run time
    import xarray

    from flex.data.results import CaseResult
    from flex.data.scene import Scene
    from flex.study import StudyOutput

Overrides = list[str] | tuple[str, ...] | Mapping[str, Any]


def override_strings(overrides: Overrides | None) -> list[str]:
    """``overrides`` (see the module doc) as ``"section.key=value"`` strings (TOML values).

    Raises :class:`~flex.base.errors.SceneError` for a key that is not ``section.key`` or a value
    TOML cannot hold (``None``, an object), :class:`TypeError` when ``overrides`` is neither
    a list of strings nor a mapping.
    """
    if overrides is None:
        return []
    if isinstance(overrides, str):
        raise ArgumentError("overrides: a list of 'section.key=value' strings or a dict, not "
                            f"one string (write [{_shown(overrides)}])")
    if not isinstance(overrides, Mapping):
        if not isinstance(overrides, list | tuple):
            raise ArgumentError(f"overrides: expected a list of 'section.key=value' strings or "
                                f"a dict, got {_kind(overrides)}")
        items = list(overrides)
        for item in items:
            if not isinstance(item, str):
                raise ArgumentError(f"overrides: expected 'section.key=value' strings, got "
                                    f"{_kind(item)}")
        return items
    from flex.data.scene_edit import override_text

    return [override_text(name, value) for name, value in _flat(overrides)]


def _flat(overrides: Mapping[str, Any]) -> list[tuple[str, Any]]:
    """``{"a.b": v}`` and ``{"a": {"b": v}}`` -> ``[("a.b", v)]``."""
    pairs = []
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise SceneError(f"override key {key!r}: expected 'section.key' or a section name")
        if isinstance(value, Mapping):
            if "." in key:
                raise SceneError(f"override {key}: a table goes under a section name, e.g. "
                                 f"{{'drive': {{'spring_preload_m': 0.011}}}}")
            pairs.extend((f"{key}.{inner}", item) for inner, item in value.items())
        elif "." not in key:
            raise SceneError(f"override {key}: expected 'section.key' (e.g. "
                             f"'drive.spring_preload_m') or a section with a table of keys")
        else:
            pairs.append((key, value))
    return pairs


def load_scene(source: str | Path | None = None, overrides: Overrides | None = None, *,
               link_models: Mapping[str, Any] | None = None) -> Scene:
    """Read a scene: a TOML file or a bundled parameter set, with overrides, validated.

    Inputs:
        source: a TOML file path, or the name of a bundled parameter set (``None``: the
            thesis's ``"cavezza2012"``, ``flex/data/scenes/cavezza2012.toml``). A file needs only
            the keys it changes; the rest come from the bundled set.
        overrides: ``"section.key=value"`` strings or a dict (module doc), applied on top.
        link_models: the link models ``crank.model`` and ``coupler.model`` may name, by name
            (None: the built-in ones, :data:`flex.dynamics.link_models.BUILTIN_LINK_MODELS`;
            a registry of one's own adds models, module doc of
            :mod:`flex.dynamics.link_models`).
    Output:
        the validated scene (a new nested dict; values in the units their keys name).
        ``"auto"`` values (``coupler.model``, ``simulation.step_s``, ...) are kept as
        written; :func:`simulate` resolves them.
    Errors:
        :class:`~flex.base.errors.SceneError`: the file is missing, unreadable, not UTF-8 or not
        TOML; an unknown section or key; a wrong type; a non-finite or out-of-range number;
        a linkage that cannot assemble (crank not shorter than coupler, slide line too far);
        inconsistent step settings; a plate that cannot be meshed sensibly.
    """
    from flex.data.scene import load_scene as _load

    return _load(_source(source), override_strings(overrides),
                 link_models=_link_models(link_models, run=False))


def derive_scene(scene: Scene, overrides: Overrides, *,
                 link_models: Mapping[str, Any] | None = None) -> Scene:
    """A new scene: ``scene`` with ``overrides`` applied, validated as a whole.

    The one way to edit a scene in a script (:func:`flex.data.scene_edit.derive_scene`, which
    the library's own edits go through too): the same parsing as ``--set``
    (:func:`flex.data.scene.apply_overrides`) and the same checks as :func:`load_scene`
    (:func:`flex.data.scene.validate`), so a derived scene is exactly what the command line would
    run with ``--set``.

    Inputs:
        scene: a scene (from :func:`load_scene` or an earlier :func:`derive_scene`); it is
            not modified.
        overrides: ``"section.key=value"`` strings or a dict (module doc), e.g.
            ``{"drive.spring_preload_m": 0.011}`` [m] or ``["coupler.model=ffrf",
            "coupler.geometry=plate", "coupler.thickness_m=0.003"]``.
        link_models: the link models a scene may name (as :func:`load_scene`).
    Output:
        the derived scene (a deep copy; ``"auto"`` values kept as written).
    Errors:
        :class:`~flex.base.errors.SceneError` as :func:`load_scene` (unknown key, type, range,
        linkage, ...), or for an override that is not ``section.key=value``;
        :class:`TypeError` when ``overrides`` is neither a list of strings nor a mapping.
    """
    from flex.data.scene_edit import derive_scene as derive

    return derive(_plain_scene(scene), override_strings(overrides),
                  link_models=_link_models(link_models, run=False))


def _link_models(given: Mapping[str, Any] | None, run: bool = True) -> Mapping[str, Any]:
    """The registry of link models: ``given``, or the built-in one (to check a scene, its
    scene-level part: nothing heavy is imported; ``run``: the entries)."""
    if given is not None:
        if not isinstance(given, Mapping):
            raise ArgumentError(f"link_models = {_shown(given)}: must be a mapping of link "
                                "model names to flex.dynamics.link_models.LinkModel entries "
                                f"(got {_kind(given)})")
        for key, entry in given.items():  # an entry under another name ran as that one
            if getattr(entry, "name", key) != key:
                raise ArgumentError(f"link_models[{_shown(key)}] is the entry named "
                                    f"{_shown(getattr(entry, 'name', None))}: a registry "
                                    f"names each entry by its own name")
        return given
    if not run:
        from flex.data.scene import BUILTIN_LINK_SCHEMAS

        return BUILTIN_LINK_SCHEMAS
    from flex.dynamics.link_models import BUILTIN_LINK_MODELS

    return BUILTIN_LINK_MODELS


def simulate(scene: Scene, name: str = "case", *, cache_dir: str | Path | None = None,
             link_models: Mapping[str, Any] | None = None, **options: Any) -> CaseResult:
    """Simulate one scene in memory and return its curves (nothing is written to disk
    except the reduction cache).

    What runs is exactly the scene: ``model = "auto"`` links are decided first (a rigid probe
    run and the fitted criterion; the choice and its reason are printed to stderr), then
    ``"auto"`` solver keys are filled by model (the calibration's solver defaults), then the
    mechanism is built in Exudyn and integrated at a fixed step from t = 0 to
    ``simulation.end_time_s``. A flexible (``ffrf``) link's Craig-Bampton reduction is built
    with NGsolve or read from the reduction cache ``cache_dir``.

    Inputs:
        scene: a validated scene (:func:`load_scene`, :func:`derive_scene`).
        name: the case name stored with the result (default ``"case"``).
        cache_dir: the reduction cache folder (default: the user's, read from the
            environment at this call; module doc).
        link_models: the link models the scene may name (as :func:`load_scene`; None: the
            built-in ones).
        options: passed on to :func:`flex.fidelity.simulation.simulate` (``reduction=``,
            ``crank_reduction=``: prebuilt reductions; ``criterion=``, ``crank_criterion=``:
            another fitted law for ``auto``, :func:`flex.fidelity.laws.load_criterion`;
            ``calibration=``: the fitted laws, FFRF rule and solver defaults every ``"auto"``
            resolves from, a :class:`flex.config.calibration.Calibration` or its name,
            ``"bundled"`` (the default) or a folder, :func:`flex.config.calibration.
            load_calibration`; ``headlines=``: the headline quantities budgeted and
            certified, a mapping of name to :class:`flex.data.headlines.Headline`,
            default the built-in ones); not needed for ordinary use.
    Output:
        a :class:`flex.data.results.CaseResult`: ``status == "ok"``; ``datasets`` maps paths of
        the result layout to :class:`flex.data.results.Dataset` (``.data`` a numpy array,
        ``.units``, ``.description``): ``"time"`` [s], ``"crank/angle"`` [rad],
        ``"crank/angular_velocity"`` [rad/s], ``"slider/position"`` [m],
        ``"joints/B/force_on_coupler"`` [N] (n, 2), ``"energy/total"`` [J], ...
        (``docs/results.md``); ``attrs`` hold the ``auto`` decisions (``fidelity_<link>_*``),
        the solver defaults used (``solver_defaults_*``) and a ``validity_warning`` when a
        linear FFRF link deflects too far to be trusted; ``scene_toml`` is the resolved
        scene; ``counters`` steps, Newton iterations and wall time [s].
    Errors:
        :class:`~flex.base.errors.SceneError`: the scene cannot run as given (too many steps, an
        output interval that is not a multiple of the step, a plate too large to mesh,
        ``auto`` refused: a lumped link, compression near buckling, ...);
        :class:`~flex.base.errors.SimulationError`: the run diverged (Newton failure, NaN,
        exploding constraint norm; the message names the step and the time and what may
        help); :class:`ImportError` only in a broken installation.
    """
    from flex.fidelity.simulation import simulate as simulate_scene
    from flex.study import check_cases, load_study

    models = _link_models(link_models)
    scene = checked_scene(scene, link_models=models)
    _check_case_name(name)
    options = _simulate_options(options)
    folder = _cache_dir(cache_dir)
    check_cases(load_study("simulate"), {name: scene}, given_keys(scene), link_models=models)
    return simulate_scene(scene, name, cache_dir=folder, link_models=models, **options)


#: the keyword arguments :func:`simulate` passes on, and what each must be
SIMULATE_OPTIONS = {"reduction": "a flex.bodies.reduction.Reduction",
                    "crank_reduction": "a flex.bodies.reduction.Reduction",
                    "criterion": "a flex.fidelity.laws.Criterion",
                    "crank_criterion": "a flex.fidelity.laws.Criterion",
                    "calibration": "a flex.config.calibration.Calibration, 'bundled' or a "
                                   "folder",
                    "headlines": "a mapping of names to flex.data.headlines.Headline"}


def _simulate_options(options: dict[str, Any]) -> dict[str, Any]:
    """:func:`simulate`'s keyword arguments checked (:data:`SIMULATE_OPTIONS`; ArgumentError
    otherwise), a calibration named by name or folder loaded."""
    _check_options(options, SIMULATE_OPTIONS, "simulate")
    _check_headlines(options.get("headlines"))
    _check_kinds(options)
    if isinstance(options.get("calibration"), str | Path):
        from flex.config.calibration import load_calibration

        options = dict(options, calibration=load_calibration(options["calibration"]))
    return options


def _cache_dir(given: str | Path | None) -> Path:
    """``given`` as a folder, or the user's reduction cache folder from the environment."""
    from flex.data.cache import REDUCTION_CACHE, check_folder

    if given is not None:
        folder = _path(given, "cache_dir", "a folder")
        check_folder(folder, REDUCTION_CACHE)
        return folder
    from flex.bodies.reduction import reduction_cache_dir

    return reduction_cache_dir(os.environ)  # the environment, read at this public edge


def run_study(name: str, source: str | Path | None = None, overrides: Overrides | None = None,
              out: str | Path | None = None, figures: bool = True, quiet: bool = False,
              *, cache_dir: str | Path | None = None, **options: Any) -> StudyOutput:
    """Run a study as ``flex run`` does: its cases, its HDF5 file, its figures and report
    (``reports/<stem>.md`` beside the file, :mod:`flex.tools.report`).

    Inputs:
        name: a study, one of :data:`flex.study.STUDIES` (``"simulate"`` runs exactly the
            given scene as one case; ``"dynamics"``, ``"kfit"``, ...: README "Studies").
        source: scene file or bundled parameter set (as :func:`load_scene`).
        overrides: ``"section.key=value"`` strings or a dict (module doc), as ``--set``.
        out: result file, ending in ``.h5`` (default ``results/<name>.h5``).
        figures: draw the study's PNG figures into ``figures/`` beside the result file.
        quiet: print nothing on success (failed cases still go to stderr).
        cache_dir: the reduction cache folder (default: the user's, read from the
            environment at this call; module doc).
        link_models: the link models the scene may name (as :func:`load_scene`; None: the
            built-in ones).
        options: passed on to :func:`flex.study.run_study` (e.g. ``sweep=``, a
            :class:`flex.sweep.SweepSettings` saying where a sweep study's cases run;
            ``environment=``, the values of the variables the study declares in
            ``ENVIRONMENT``, by default read from the environment at this call, as
            ``flex run`` does: ``FLEX_BENCH_MAKE=0`` skips the bench study's ``make all``).
    Output:
        a :class:`flex.study.StudyOutput`: ``results`` (case name -> CaseResult, as
        :func:`simulate` returns), ``summary`` (``datasets`` stored under ``/summary``,
        ``report`` the printed text), ``path`` (the file written), ``figures``,
        ``wall_time_s`` [s] and ``as_expected`` (every case ended as the study declares).
        The file is written atomically; with a failed case that the study does not expect
        and an existing file at ``out``, it goes beside it as ``<name>.failed.h5``. Failed
        cases do not raise: check ``as_expected`` or each case's ``status``.
    Errors:
        :class:`~flex.base.errors.FlexError` before anything runs: an unknown study, a bad scene
        or override (:class:`~flex.base.errors.SceneError`, also for a key the study would not
        use), an output that cannot be written or would overwrite an input
        (:class:`~flex.base.errors.OutputError`); :class:`flex.study.Interrupted` (a
        :class:`KeyboardInterrupt`) on Ctrl-C, naming the files already written.
    """
    from flex.study import STUDIES, from_environment
    from flex.study import run_study as _run

    if not isinstance(name, str) or name not in STUDIES:
        raise ArgumentError(f"name: {_kind(name)} is not a study; accepted: "
                            f"{', '.join(STUDIES)}")
    source = _source(source)
    out = None if out is None else _path(out, "out", "a result file path ending in .h5")
    for flag, value in (("figures", figures), ("quiet", quiet)):
        if not isinstance(value, bool):
            raise ArgumentError(f"{flag}: expected True or False, got {_kind(value)}")
    _check_options(options, {"sweep": "a flex.sweep.SweepSettings or None",
                             "environment": "a dict of environment variable names to "
                                            "strings"}, "run_study")
    _check_study_options(options)
    edge = from_environment(name, os.environ)  # the environment, read at this public edge
    options.setdefault("environment", edge["environment"])
    folder = edge["cache_dir"] if cache_dir is None else _cache_dir(cache_dir)
    return _run(name, source, override_strings(overrides), out, figures, quiet,
                cache_dir=folder, **options)


def open_result(path: str | Path, case: str | None = None) -> xarray.Dataset:
    """One case of a flex result file as an ``xarray.Dataset`` (read into memory, file
    closed on return).

    Inputs:
        path: a result file written by flex (``results/<study>.h5``, a ``--out`` file, a
            reference-curve file).
        case: the case name (``"preload_22mm"``); may be omitted when the file has one case.
    Output:
        an ``xarray.Dataset`` with coordinate ``time`` [s]; variables named by their path in
        the case (``ds["crank/angle"]``), each with ``units``, ``description`` and
        ``long_name`` attributes (so ``.plot()`` labels its axes); two-column curves have a
        dimension ``xy`` (``"x"``, ``"y"``). ``ds.attrs`` hold the case's attributes and
        the file's provenance (prefixed ``file_``). See :func:`flex.data.results.to_xarray`.
    Errors:
        :class:`~flex.base.errors.ResultFileError`: the file is missing, truncated, not HDF5 or
        not written by flex, or xarray is not installed (``pip install xarray``);
        :class:`flex.data.results.ResultPathError` (a ResultFileError): no such case, or no
        ``case`` given for a file with several cases (the message lists them).
    """
    from flex.data.results import to_xarray

    path = _path(path, "path", "a result file path")
    if case is not None and not isinstance(case, str):
        raise ArgumentError(f"case: expected a case name (a string) or None, got {_kind(case)}")
    return to_xarray(path, case)


# ------------------------------------------------------------------------------------------
# argument checks: the command line's rules for what a script hands over
# ------------------------------------------------------------------------------------------
def _kind(value: Any) -> str:
    """``value`` described in an error message: its type and a short repr."""
    return f"{type(value).__name__} {_shown(value)}"


def _shown(value: Any, limit: int = 60) -> str:
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - a repr that fails is still an argument to name
        text = f"<{type(value).__name__}>"
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _path(value: Any, argument: str, what: str) -> Path:
    """A str or path-like argument as a :class:`Path` (not empty), else ArgumentError."""
    if isinstance(value, bytes) or not isinstance(value, str | os.PathLike):
        raise ArgumentError(f"{argument}: expected {what} (a str or pathlib.Path), got "
                            f"{_kind(value)}")
    text = os.fspath(value)
    if not isinstance(text, str) or not text.strip():
        raise ArgumentError(f"{argument}: expected {what}, got an empty path")
    return Path(text)


def _source(source: Any) -> str | Path | None:
    """A scene source: None, a bundled parameter set's name or a TOML file path."""
    if source is None:
        return None
    if isinstance(source, Mapping):
        raise ArgumentError("source: expected a scene file path or the name of a bundled "
                            "parameter set, got a dict (a scene already loaded): pass its "
                            "changes as overrides=, or write it to a file with "
                            "flex.data.scene.to_toml")
    return _path(source, "source", "a scene file path or bundled parameter set name")


def _plain_scene(scene: Any, argument: str = "scene") -> dict[str, dict[str, Any]]:
    """A copy of a scene handed over by a caller, as plain dicts of plain values: a
    mapping of section names to mappings of keys (numpy scalars become Python numbers).
    Nothing is validated here beyond that shape."""
    if not isinstance(scene, Mapping):
        hint = ""
        if isinstance(scene, str | os.PathLike):
            hint = f"; read it first: load_scene({_shown(os.fspath(scene))})"
        raise ArgumentError(f"{argument}: expected a scene (the dict load_scene or "
                            f"derive_scene returns), got {_kind(scene)}{hint}")
    plain: dict[str, dict[str, Any]] = {}
    for section, table in scene.items():
        if not isinstance(section, str):
            raise SceneError(f"{argument}: section name {_shown(section)} is not a string")
        if not isinstance(table, Mapping):
            raise SceneError(f"{argument}: [{section}] must be a table of keys (a dict), got "
                             f"{_kind(table)}")
        plain[section] = {}
        for key, value in table.items():
            if not isinstance(key, str):
                raise SceneError(f"{argument}: key {_shown(key)} in [{section}] is not a "
                                 f"string")
            if hasattr(value, "item") and getattr(value, "shape", None) == ():
                value = value.item()  # a numpy scalar -> the Python number it holds
            plain[section][key] = value
    return plain


def checked_scene(scene: Any, argument: str = "scene", *,
                  link_models: Mapping[str, Any] | None = None) -> Scene:
    """A validated copy of a scene a caller hands over (:func:`_plain_scene`, then
    :func:`flex.data.scene.validate`: the checks ``--scene`` and ``--set`` get); raises
    :class:`~flex.base.errors.ArgumentError` or :class:`~flex.base.errors.SceneError`."""
    from flex.data.scene import validate

    plain = _plain_scene(scene, argument)
    if link_models is None:
        validate(plain)
    else:
        validate(plain, link_models)
    return plain


def given_keys(scene: Scene) -> dict[str, Any]:
    """The values of ``scene`` that differ from the bundled scene's, ``{"section.key":
    value}``: what a caller changed, as :func:`flex.config.usage.explicit_keys` counts a
    scene file's keys."""
    from flex.data.scene import default_scene

    bundled = default_scene()
    return {f"{section}.{key}": value for section, table in scene.items()
            for key, value in table.items() if bundled[section].get(key) != value}


def _check_case_name(name: Any) -> None:
    if not isinstance(name, str) or not name.strip() or "/" in name or not name.isprintable():
        raise ArgumentError(f"name: expected a case name (a non-empty string without '/' or "
                            f"control characters), got {_kind(name)}")


def _check_options(options: Mapping[str, Any], accepted: Mapping[str, str], function: str
                   ) -> None:
    for key in options:
        if key not in accepted:
            listed = "; ".join(f"{name}: {what}" for name, what in accepted.items())
            raise ArgumentError(f"{function}: unknown keyword argument {key!r}; accepted "
                                f"beside the named ones: {listed}")


def _check_kinds(options: Mapping[str, Any]) -> None:
    """The calibration and criteria of :data:`SIMULATE_OPTIONS` of their kinds (``calibration
    = 123`` came back as an AttributeError from inside the run)."""
    from flex.config.calibration import Calibration
    from flex.fidelity.laws import Criterion

    kinds = {"calibration": (Calibration, str, Path), "criterion": (Criterion,),
             "crank_criterion": (Criterion,)}
    for key, accepted in kinds.items():
        value = options.get(key)
        if value is not None and (isinstance(value, bool) or not isinstance(value, accepted)):
            raise ArgumentError(f"{key} = {_shown(value)}: must be {SIMULATE_OPTIONS[key]} "
                                f"(got {_kind(value)})")


def _check_headlines(headlines: Any) -> None:
    from flex.data.headlines import Headline

    if headlines is not None and not (isinstance(headlines, Mapping) and all(
            isinstance(name, str) and isinstance(entry, Headline) and entry.name == name
            for name, entry in headlines.items())):
        raise ArgumentError(f"headlines: expected a mapping of names to "
                            f"flex.data.headlines.Headline entries of the same names, got "
                            f"{_kind(headlines)}")


def _check_study_options(options: Mapping[str, Any]) -> None:
    sweep = options.get("sweep")  # flex.sweep is a higher layer: its fields, not its class
    if sweep is not None and not all(hasattr(sweep, name) for name in (
            "scheduler", "workers", "folder", "retry_failed", "progress")):
        raise ArgumentError(f"sweep: expected a flex.sweep.SweepSettings or None, got "
                            f"{_kind(sweep)}")
    environment = options.get("environment")
    if environment is not None and not (isinstance(environment, Mapping) and all(
            isinstance(k, str) and isinstance(v, str) for k, v in environment.items())):
        raise ArgumentError(f"environment: expected a dict of variable names to strings, got "
                            f"{_kind(environment)}")


__all__ = ["load_scene", "derive_scene", "simulate", "run_study", "open_result"]
