"""``"auto"``, decided once: every ``"auto"`` of a scene turned into a concrete value, with
the reasons, as one value.

:func:`resolve` is the one place a scene's ``"auto"`` values are decided, in this order:

1. ``drive.spring_model`` (:func:`flex.fidelity.spring_choice.decide_spring`, from the rigid
   probe of :mod:`flex.fidelity.probe`);
2. the links' ``model`` (:func:`decide_links`): rigid when the deflection the probe's loads
   predict meets ``fidelity.tolerance`` (relative to the link's length), else the lowest
   flexible rung of the ladder whose measured model error meets the tolerance relative to
   the deflection (:func:`flex.config.ladder.climb`: the FFRF body), else the highest (the
   nonlinear FE coupler); an FFRF link's modes with it;
3. the links' ``modes`` and ``mesh_size_m`` and the ``[simulation]`` solver keys
   (:func:`flex.config.settings.resolve_solver_settings`: the FFRF settings rule, the solver
   defaults).

It returns a :class:`Resolution`: the concrete scene (no ``"auto"`` anywhere), the
decisions and the solver choice, each with its reason; the decisions are printed to stderr
(one line each) unless ``quiet``. Everything below takes concrete scenes only
(:func:`flex.dynamics.solver.integrate` refuses ``"auto"``). :func:`check` refuses, before
anything runs, a scene none of whose possible resolutions can run (the policy of what each
``"auto"`` may become is :func:`candidates`, the probe's :func:`flex.fidelity.probe.probe_scene`:
both written once, here and there). Each scene is resolved once: :func:`resolve` reuses the
check's resolution of the candidate it decides for.
"""

from __future__ import annotations

import copy
import itertools
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.errors import SceneError
from flex.base.physics import (
    IN_PLANE_KINDS,
    TWO_PI,
    Plate,
    n_values,
    plate_thickness_for_mass_m,
)
from flex.config.calibration import Calibration
from flex.config.knobs import ELEMENTS, MODES
from flex.config.ladder import climb
from flex.config.settings import (
    AUTO,
    SolverChoice,
    check_concrete,
    resolve_link_keys,
    resolve_solver_settings,
)
from flex.config.tolerance import Tolerance
from flex.data.plates import EXACT_BEAM_ELEMENTS
from flex.data.scene import LINKS, Scene, check_meshed_plate, model_names, to_toml
from flex.dynamics.link_models import (
    BUILTIN_LINK_MODELS,
    FFRF,
    RIGID,
    LinkModel,
)
from flex.fidelity.criteria import (
    EULER_LOAD_LIMIT,
    euler_load_ratio,
)
from flex.fidelity.laws import Criterion, criterion_of
from flex.fidelity.predictor import PREDICTION_MARGIN, predict_deflection
from flex.fidelity.probe import FidelityDecision, deployment_probe, probe_scene
from flex.fidelity.spring_choice import decide_spring


# ------------------------------------------------------------------------------------------
# the one resolution
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Resolution:
    """A scene's ``"auto"`` values decided: the concrete ``scene``, the link and spring
    ``decisions`` and the ``solver`` choice (None: no ``"auto"`` solver or link key)."""

    scene: Scene
    decisions: tuple[FidelityDecision, ...] = ()
    solver: SolverChoice | None = None

    def attrs(self) -> dict[str, Any]:
        """Result-file attributes: ``fidelity_<link>_*`` and ``solver_defaults_*``."""
        out: dict[str, Any] = {}
        for decision in self.decisions:
            out.update(decision.attrs())
        if self.solver is not None:
            out.update(self.solver.attrs())
        return out


def has_auto_models(scene: Mapping[str, Mapping[str, Any]]) -> bool:
    """Whether a link's model or the spring's model is ``"auto"``."""
    return (AUTO in (scene["crank"]["model"], scene["coupler"]["model"])
            or scene["drive"]["spring_model"] == AUTO)


def candidates(scene: Scene, link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
               ) -> list[Scene]:
    """The concrete-model scenes ``"auto"`` link models may turn ``scene`` into (itself if
    none): a link ``"auto"`` may become rigid or FFRF (the nonlinear FE coupler, past them,
    runs at the rigid step too), a lumped crank or one with a constant-speed drive only
    rigid (a flexible verdict is refused there); an ``"auto"`` spring is taken massless (the
    checks do not depend on it). What ``"auto"`` may become: the models of ``link_models``
    ``auto`` may pick (``auto_choice``) short of the reference (which runs at the rigid
    step too), rigid ones only where a flexible verdict is refused."""
    if scene["drive"]["spring_model"] == AUTO:
        scene = copy.deepcopy(scene)
        scene["drive"]["spring_model"] = "massless"
    choices = []
    for link in LINKS:
        values = scene[link]
        if values["model"] != AUTO:
            choices.append([values["model"]])
        elif link == "crank" and (values["geometry"] != "plate"
                                  or scene["drive"]["kind"] != "spring"):
            choices.append(model_names(link, link_models, auto_choice=True, rigid=True))
        else:
            choices.append(model_names(link, link_models, auto_choice=True, reference=False))
    if all(len(options) == 1 and options[0] == scene[link]["model"]
           for options, link in zip(choices, LINKS, strict=True)):
        return [scene]
    out = []
    for crank, coupler in itertools.product(*choices):
        candidate = copy.deepcopy(scene)
        candidate["crank"]["model"], candidate["coupler"]["model"] = crank, coupler
        out.append(candidate)
    return out


def check(scene: Scene, calibration: Calibration | None = None, *,
          link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS
          ) -> dict[str, tuple[Scene, SolverChoice | None]]:
    """Refuse, before anything is built, meshed or simulated, a scene none of whose
    resolutions can run (:class:`SceneError`, one line naming the key and the accepted
    range): refinement without the error budget it follows; every candidate
    (:func:`candidates`) resolved and checked
    (:func:`flex.config.settings.check_concrete`), refused only when every one fails (a
    check that fails for only some choices is left to the run, which then stores a failed
    case naming it); with ``"auto"`` models, the rigid probe must fit the step limit
    (:func:`flex.fidelity.probe.probe_scene`). Returns the candidates that passed, resolved,
    by their TOML (what :func:`resolve` reuses). Takes milliseconds. ``calibration``: what
    the ``"auto"`` values resolve from (None: the bundled calibration); ``link_models``: the
    registry of the scene's link models."""
    if scene["fidelity"]["refine"] and not scene["simulation"]["error_estimate"]:
        raise SceneError("fidelity.refine = true with simulation.error_estimate = false: "
                         "refinement follows the error budget; set error_estimate = true or "
                         "refine = false")
    # an "auto" link's plate too: what it may mesh
    linked, _ = resolve_link_keys(scene, calibration, link_models=link_models)
    for link in LINKS:
        check_meshed_plate(link, linked[link], link_models)
    options = candidates(scene, link_models)
    passed: dict[str, tuple[Scene, SolverChoice | None]] = {}
    errors: list[SceneError] = []
    for candidate in options:
        try:
            resolved, choice = resolve_solver_settings(candidate, calibration,
                                                       link_models=link_models)
            check_concrete(resolved, choice, link_models=link_models)
            passed[to_toml(candidate)] = (resolved, choice)
        except SceneError as exc:
            errors.append(exc)
    if not passed:
        if len(options) == 1:
            raise errors[0]
        raise SceneError(f'{errors[0]} (for every model "auto" may choose)')
    if len(options) > 1 or AUTO in (scene["crank"]["model"], scene["coupler"]["model"]):
        probe_scene(scene, calibration=calibration)
    return passed


def resolve(scene: Scene, criterion: Criterion | None = None,
            crank_criterion: Criterion | None = None, *, cache_dir: Path | None = None,
            quiet: bool = False, calibration: Calibration | None = None,
            link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS) -> Resolution:
    """Decide every ``"auto"`` of a validated scene (see the module doc); raises
    :class:`SceneError` for a scene that cannot run or an ``auto`` that refuses.
    ``criterion`` / ``crank_criterion``: the coupler's and the crank's fitted laws (None:
    ``calibration``'s); ``cache_dir``: the reduction cache folder of the crank's frequency
    analysis (None: in memory); ``calibration``: the laws, FFRF rule and solver defaults the
    ``"auto"`` values resolve from (:mod:`flex.config.calibration`; None: the bundled one);
    ``link_models``: the registry of the scene's link models (the fitted laws decide rigid
    or flexible; past rigid, ``auto`` climbs the ladder of ``link_models``' rungs)."""
    passed = check(scene, calibration, link_models=link_models)
    decisions: list[FidelityDecision] = []
    concrete = scene
    if concrete["drive"]["spring_model"] == AUTO:
        concrete = copy.deepcopy(concrete)
        decisions.append(decide_spring(concrete))
    if AUTO in (concrete["crank"]["model"], concrete["coupler"]["model"]):
        concrete, links = decide_links(concrete, criterion, crank_criterion,
                                       cache_dir=cache_dir, calibration=calibration,
                                       link_models=link_models)
        decisions += links
    reused = passed.get(to_toml(concrete))
    resolved, choice = (reused if reused is not None
                        else resolve_solver_settings(concrete, calibration,
                                                     link_models=link_models))
    if reused is None:
        check_concrete(resolved, choice, link_models=link_models)
    if not quiet:
        for decision in decisions:
            modes = f" ({decision.modes} modes)" if decision.modes else ""
            key = ("drive.spring_model" if decision.link == "spring"
                   else f"{decision.link}.model")
            print(f"flex: fidelity: {key} = auto -> {decision.model}{modes}: "
                  f"{decision.reason}", file=sys.stderr)
    return Resolution(resolved, tuple(decisions), choice)


# ------------------------------------------------------------------------------------------
# the links' models
# ------------------------------------------------------------------------------------------
MAX_AUTO_MODES = 24
MIN_AUTO_MODES = 2


def modes_for_cutoff(scene: Mapping[str, Mapping[str, Any]], omega_cut_rad_per_s: float,
                     link: str = "coupler") -> int:
    """Fixed-interface modes to keep: every estimated clamped mode below ``omega_cut``.

    A mode whose own n = delta_t * omega_mode reaches k(tolerance) responds quasi-statically
    within the tolerance, and the Craig-Bampton static modes carry that response; modes below
    the cut respond dynamically and are kept. At least the first in-plane bending mode (and
    every mode below it) is kept, at least :data:`MIN_AUTO_MODES`, at most
    :data:`MAX_AUTO_MODES`. ``link``: ``"coupler"`` or ``"crank"`` (plate geometry).
    """
    c = scene[link]
    in_plane = c.get("mode_selection") == "in_plane"  # the reduction keeps only these kinds
    estimates = Plate.of(c).clamped_frequencies((4 if in_plane else 1) * (MAX_AUTO_MODES + 10))
    if in_plane:
        estimates = [(omega, kind) for omega, kind in estimates if kind in IN_PLANE_KINDS]
    first_in_plane = next(i for i, (_, kind) in enumerate(estimates) if kind == "in_plane")
    below = sum(1 for omega, _ in estimates if omega < omega_cut_rad_per_s)
    return int(min(MAX_AUTO_MODES, max(MIN_AUTO_MODES, first_in_plane + 1, below)))


def _decide(link: str, omega: float, delta_t_s: float, how: str, tolerance: float,
            criterion: Criterion, damping_ratio: float,
            omega_how: str = "Euler-Bernoulli pinned-pinned",
            ) -> tuple[FidelityDecision, float]:
    ratio, law = criterion.law(damping_ratio)
    n = n_values(delta_t_s, omega)
    k_phys = law.k(tolerance, "physical", bound="upper")
    predicted = float(law.band(n["physical"], "physical", kind="prediction")[1])
    extrapolated = law.extrapolated(n["physical"])
    rigid = n["physical"] >= k_phys
    verdict = RIGID if rigid else FFRF
    reason = (f"{link}: n = delta_t/T = {n['physical']:.4g} (T = 2 pi/omega; thesis "
              f"convention delta_t*omega = {n['thesis']:.4g}) {'>=' if rigid else '<'} "
              f"k = {k_phys:.4g} ({k_phys * TWO_PI:.4g} thesis) for tolerance "
              f"{tolerance:g} on the governing error (95 % upper prediction band, damping "
              f"ratio {ratio:g} law); predicted error <= {predicted:.3g}; {how}; omega = "
              f"{omega:.5g} rad/s ({omega_how})"
              + ("; n outside the fitted range: extrapolated" if extrapolated else ""))
    decision = FidelityDecision(link, verdict, None, reason, tolerance, delta_t_s, omega,
                                n["physical"], n["thesis"], k_phys, predicted, extrapolated)
    return decision, k_phys


def equivalent_crank_plate(scene: Mapping[str, Mapping[str, Any]]) -> dict[str, dict[str, Any]]:
    """The scene with a lumped crank replaced by a plate of the same mass and length.

    The plate keeps the crank's ``width_m`` and material; its thickness (the in-plane bending
    height) is mass / (density x length x width). Plate cranks are returned unchanged (a copy).
    """
    import copy

    out = copy.deepcopy({k: dict(v) for k, v in scene.items()})
    crank = out["crank"]
    if crank["geometry"] == "lumped":
        crank["thickness_m"] = plate_thickness_for_mass_m(crank["mass_kg"], crank["length_m"],
                                                          crank["width_m"],
                                                          crank["density_kg_per_m3"])
        crank["geometry"] = "plate"
    return out


#: the eigen-solve whose first modes the crank's frequency analysis keeps
#: (:func:`crank_elastic_omega`): as many as the full FFRF crank's of the crank study (and of
#: lawfit), so that analysis and full run share one mesh and solve per plate (the crank study
#: analysed each of its 17 scenes on a mesh and solve of its own, ~2 s each); elsewhere it
#: costs a 12-mode solve instead of a 4-mode one (~0.5 s more, once per plate and cache)
CRANK_ANALYSIS_SOLVE_MODES = 12


def crank_elastic_omega(scene: Mapping[str, Mapping[str, Any]], *,
                        cache_dir: Path | None = None) -> float:
    """First in-plane elastic circular frequency [rad/s] of the crank in the mechanism.

    Contract: ``scene`` with a plate crank (see :func:`equivalent_crank_plate`). The
    mechanism is assembled at t = 0 twice, with the crank as an FFRF body (enough
    fixed-interface modes to hold its first in-plane bending mode, at least 4) and as a
    rigid body, the coupler rigid in both; Exudyn's constrained eigenvalue analysis gives
    their frequencies. Modes that move the coupler out of the mechanism plane (crank
    torsion and out-of-plane bending, which planar loads do not excite) are dropped; of the
    in-plane ones, the one nearest the rigid model's mechanism mode (the slider on its
    spring) is the rigid-body mode, and the lowest other is returned.

    Why not the plate's pinned-pinned frequency, as for the coupler: with a wing welded at
    A the crank is a cantilever from the wing's inertia carrying the coupler and slider at B
    (measured on a 1 mm crank: 68 Hz in the mechanism, 1430 Hz pinned-pinned); without a
    wing the analysis returns the pinned-pinned value (1442 Hz).

    ``cache_dir``: the reduction cache folder the FFRF crank's reduction is loaded from or
    written to (None: built in memory, no disk cache). That reduction keeps the first modes
    of a :data:`CRANK_ANALYSIS_SOLVE_MODES`-mode solve of the plate (one mesh and one
    eigen-solve per plate for the analysis and a full FFRF crank of as many modes).
    """
    import copy

    from flex.dynamics.link_models import reduction_for_scene
    from flex.dynamics.mechanism import build_mechanism

    analysis = copy.deepcopy({k: dict(v) for k, v in scene.items()})
    analysis["coupler"]["model"] = RIGID
    crank = analysis["crank"]
    estimates = Plate.of(crank).clamped_frequencies()
    first_in_plane = next(i for i, (_, kind) in enumerate(estimates) if kind == "in_plane")
    crank["modes"] = max(4, first_in_plane + 2)

    def in_plane_omegas(model: str) -> np.ndarray:
        crank["model"] = model
        reduction = (reduction_for_scene(
            analysis, "crank", cache_dir=cache_dir,
            solve_modes=max(crank["modes"], CRANK_ANALYSIS_SOLVE_MODES))
            if model == FFRF else None)
        # 3D for both models: the modes are sorted by their out-of-plane coordinates
        mech = build_mechanism(analysis, None, reduction, planar=False)
        values, vectors = mech.mbs.ComputeODE2Eigenvalues(useAbsoluteValues=True)
        values, vectors = np.abs(np.asarray(values)), np.asarray(vectors)
        index = mech.mbs.GetNodeODE2Index(mech.coupler["node"])
        arm = analysis["coupler"]["length_m"]
        block = vectors[index:index + 6]  # coupler x y z rx ry rz
        in_plane = np.sqrt(block[0] ** 2 + block[1] ** 2 + (arm * block[5]) ** 2)
        out_of_plane = np.sqrt(block[2] ** 2 + (arm * block[3]) ** 2 + (arm * block[4]) ** 2)
        return np.sort(np.sqrt(values[in_plane > out_of_plane]))

    rigid = in_plane_omegas(RIGID)
    flexible = in_plane_omegas(FFRF)
    if len(rigid) != 1 or len(flexible) < 2:
        raise SceneError(f"crank frequency analysis: expected one in-plane rigid-body mode and "
                         f"at least one elastic mode, found {len(rigid)} and "
                         f"{max(len(flexible) - 1, 0)}; set crank.model explicitly")
    elastic = np.delete(flexible, np.argmin(np.abs(flexible - rigid[0])))
    return float(elastic[0])


def decide_links(scene: Mapping[str, Mapping[str, Any]],
                     criterion: Criterion | None = None,
                     crank_criterion: Criterion | None = None, *,
                     cache_dir: Path | None = None, calibration: Calibration | None = None,
                     link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
                     ) -> tuple[dict[str, dict[str, Any]], list[FidelityDecision]]:
    """Replace ``"auto"`` link models by concrete ones; return the scene and the decisions.

    Contract: ``scene`` is validated, its spring model concrete. ``coupler.model = "auto"``
    (plate geometry) becomes ``"rigid"`` when the deflection error the rigid probe's own
    loads predict (:mod:`flex.fidelity.predictor`), times its margin, meets the tolerance,
    else the FFRF body when its model error meets it (:func:`_climb`), else the nonlinear FE
    coupler, with ``coupler.modes`` from :func:`modes_for_cutoff` at ``omega_cut = k /
    delta_t`` (thesis convention: every mode with n below k is kept); the n-law's verdict
    (rigid when n >= k(tolerance), conservative k, :meth:`ErrorLaw.k` ``upper``) stays in the
    reason and the attributes as the baseline.
    ``crank.model = "auto"`` is decided the same way, with the crank's own law
    (``crank_criterion``, default ``calibration``'s, :func:`flex.fidelity.laws.criterion_of`)
    and its first in-plane elastic frequency in the assembled mechanism
    (:func:`crank_elastic_omega`; a lumped crank is analysed as a plate of its mass,
    :func:`equivalent_crank_plate`), and its deflection error predicted from the probe's loads
    (deciding without a wing, stored beside the n-law's verdict with one:
    :func:`_crank_by_loads`): ``"rigid"``, or ``"ffrf"`` with its modes for a plate crank; a
    lumped crank the criterion calls flexible, or a flexible one with a constant-speed drive, is
    refused with a :class:`SceneError`. A coupler loaded beyond :data:`EULER_LOAD_LIMIT` of its
    Euler load is not offered rigid (outside the fit): the ladder's rungs decide, each within
    the compression its bound was measured at (:func:`flex.config.ladder.climb`).
    ``drive.spring_model = "auto"`` must be resolved before (:func:`resolve` does it first, with
    :func:`flex.fidelity.spring_choice.decide_spring`). Scenes without ``auto`` are returned
    unchanged (a copy). ``cache_dir``: the reduction cache folder of the crank's frequency
    analysis (None: its reduction is built in memory, no disk cache).
    """
    import copy

    resolved = copy.deepcopy({k: dict(v) for k, v in scene.items()})
    coupler, crank = resolved["coupler"], resolved.get("crank", {})
    wants_coupler = coupler.get("model") == AUTO
    wants_crank = crank.get("model") == AUTO
    decisions: list[FidelityDecision] = []
    if not (wants_coupler or wants_crank):
        return resolved, decisions
    criterion = criterion or criterion_of(calibration, "coupler")
    tolerance = Tolerance.of(resolved).relative
    links = " and ".join(f"{link}.model" for link, wants in
                         (("coupler", wants_coupler), ("crank", wants_crank)) if wants)
    try:
        delta_t_s, how, probe = deployment_probe(resolved, calibration)
    except SceneError as refused:  # say which links are "auto"
        raise SceneError(f'{links} = "auto": '
                         + str(refused).removeprefix('model = "auto": ')) from None
    if not delta_t_s > 0:  # a mechanism that does not move (no preload): no time scale
        raise SceneError(f'{links} = "auto": the rigid run does not deploy (delta_t = '
                         f"{delta_t_s:g} s: the crank angle's first maximum is at t = 0; "
                         f"drive.spring_preload_m = {resolved['drive']['spring_preload_m']:g} "
                         f"m), so the criterion has no time scale; give the spring a preload "
                         f'> 0 or set the link model ("rigid", "ffrf")')
    if wants_coupler:
        decision, how = _decide_coupler(resolved, probe, delta_t_s, how, tolerance, criterion,
                                        calibration, link_models, cache_dir)
        decisions.append(decision)
    if wants_crank:
        decisions.append(_decide_crank(resolved, probe, delta_t_s, how, tolerance,
                                       crank_criterion or criterion_of(calibration, "crank"),
                                       cache_dir, calibration))
    return resolved, decisions


def _mode_cut(decision: FidelityDecision, resolved: dict[str, dict[str, Any]], link: str,
              k_phys: float, delta_t_s: float, calibration: Calibration | None = None) -> None:
    """An ``ffrf`` decision keeps every estimated mode below omega_cut = k / delta_t; a link
    whose ``modes`` is ``"auto"`` gets the tolerance rule's instead (:mod:`flex.config.
    ffrf_rule`, with the mesh and the step)."""
    if resolved[link]["modes"] == AUTO:
        from flex.config.ffrf_rule import fill_link_keys

        decision.modes = fill_link_keys(resolved, link, decision.tolerance,
                                        calibration)["modes"]
        decision.reason += (f"; modes = {decision.modes}: the tolerance rule's "
                            f"(flex.config.ffrf_rule)")
        return
    omega_cut = k_phys * TWO_PI / delta_t_s
    decision.modes = modes_for_cutoff(resolved, omega_cut, link)
    resolved[link]["modes"] = decision.modes
    decision.reason += (f"; modes = {decision.modes}: every estimated fixed-interface "
                        f"mode below omega_cut = k/delta_t = {omega_cut:.4g} rad/s")


def _decide_coupler(resolved: dict[str, dict[str, Any]], probe: dict[str, np.ndarray],
                    delta_t_s: float, how: str, tolerance: float, criterion: Criterion,
                    calibration: Calibration | None = None,
                    link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
                    cache_dir: Path | None = None) -> tuple[FidelityDecision, str]:
    """The coupler's decision (near buckling, beyond :data:`EULER_LOAD_LIMIT` x its Euler
    load, rigid is not offered and the ladder decides); returns it and ``how`` with the
    compressive load added."""
    coupler = resolved["coupler"]
    plate = Plate.of(coupler)
    omega = plate.pinned_pinned_omega
    ratio = euler_load_ratio(probe["joints/B/force_on_coupler"],
                             probe["joints/C/force_on_coupler"], probe["coupler/angle"], plate)
    how += f"; compressive load {ratio:.3g} x Euler load"
    decision, k_phys = _decide("coupler", omega, delta_t_s, how, tolerance, criterion,
                               float(coupler["damping_ratio"]))
    if ratio > EULER_LOAD_LIMIT:  # the fitted laws stop here: no rigid, the ladder decides
        decision.model = FFRF
        decision.reason += (f"; beyond {EULER_LOAD_LIMIT:g} x the Euler load the fitted laws "
                            f"do not hold and the rigid model is not offered (near buckling "
                            f"the error depends on the load, not on n)")
    else:
        _decide_by_loads(decision, predict_deflection(probe, coupler).relative_error(
            coupler["length_m"]), tolerance)
    if link_models[decision.model].rigid and Tolerance.of(resolved).wants_flexible("coupler"):
        decision.model = FFRF  # asked of itself, its deflection needs a flexible rung
        decision.reason += ("; fidelity.quantities asks the coupler's own deflection, which a "
                            "rigid coupler gives as a +-25 % prediction only: a flexible rung")
    if not link_models[decision.model].rigid:
        _climb(decision, coupler, ratio, tolerance, link_models, cache_dir)
    coupler["model"] = decision.model
    if MODES.name in link_models[decision.model].knobs:
        _mode_cut(decision, resolved, "coupler", k_phys, delta_t_s, calibration)
    if ELEMENTS.name in link_models[decision.model].knobs \
            and coupler.get("elements") == EXACT_BEAM_ELEMENTS:
        coupler["elements"] = AUTO  # auto picked the beam: its elements follow the tolerance
    return decision, how


def _climb(decision: FidelityDecision, coupler: dict[str, Any], load_ratio: float,
           tolerance: float, link_models: Mapping[str, LinkModel] = BUILTIN_LINK_MODELS,
           cache_dir: Path | None = None) -> None:
    """Past rigid, the lowest rung of the ladder whose measured model error relative to the
    deflection meets ``tolerance`` (:func:`flex.config.ladder.climb`), else the highest
    (in place: ``decision.model``; refused when that model has no damping and the coupler
    is damped)."""
    chosen = climb("coupler", coupler, load_ratio, tolerance, link_models, cache_dir)
    decision.reason += f"; ladder: {chosen.model} ({chosen.reason})"
    if not link_models[chosen.model].damped and coupler["damping_ratio"] != 0:
        raise SceneError(f'coupler.model = "auto": {decision.reason}; the '
                         f"{link_models[chosen.model].label} coupler has no damping model: "
                         f"set coupler.damping_ratio = 0, or a larger fidelity.tolerance")
    decision.model = chosen.model


def _decide_by_loads(decision: FidelityDecision, predicted_rigid_error: float,
                     tolerance: float) -> None:
    """Let the rigid model's error predicted from the probe's loads decide (in place), the
    n-law's verdict staying in the reason as the baseline: rigid when the prediction times
    :data:`flex.fidelity.predictor.PREDICTION_MARGIN` meets ``tolerance``."""
    decision.predicted_rigid_error = predicted_rigid_error
    bound = predicted_rigid_error * PREDICTION_MARGIN
    rigid = bound <= tolerance
    baseline = decision.model
    decision.model = RIGID if rigid else FFRF
    decision.reason = (
        f"{decision.link}: the rigid run's loads predict a deflection of "
        f"{predicted_rigid_error:.3g} of the {decision.link}'s length, the rigid model's error "
        f"of the motion (x {PREDICTION_MARGIN:g} margin: {bound:.3g} "
        f"{'<=' if rigid else '>'} tolerance {tolerance:g}); n-law baseline ("
        f"{'agrees' if baseline == decision.model else f'would pick {baseline}'}): "
        + decision.reason.split(": ", 1)[1])


def _decide_crank(resolved: dict[str, dict[str, Any]], probe: dict[str, np.ndarray],
                  delta_t_s: float, how: str, tolerance: float, crank_criterion: Criterion,
                  cache_dir: Path | None = None, calibration: Calibration | None = None
                  ) -> FidelityDecision:
    """The crank's decision from its own law and its in-mechanism frequency (its reduction
    cached in ``cache_dir``, None: in memory), then from the ``probe``'s loads
    (:func:`_crank_by_loads`); a flexible verdict for a lumped crank or with a
    constant-speed drive is refused."""
    crank = resolved["crank"]
    lumped = crank["geometry"] == "lumped"
    plate_scene = equivalent_crank_plate(resolved)
    plate = plate_scene["crank"]
    omega = crank_elastic_omega(plate_scene, cache_dir=cache_dir)
    if lumped:
        how += (f"; lumped crank as a plate of its mass: {plate['width_m'] * 1e3:g} mm wide, "
                f"{plate['thickness_m'] * 1e3:.3g} mm high")
    decision, k_phys = _decide(
        "crank", omega, delta_t_s, how, tolerance, crank_criterion,
        float(crank["damping_ratio"]),
        omega_how="first in-plane elastic mode of the crank in the assembled mechanism, "
                  "Exudyn eigenvalues at t = 0")
    _crank_by_loads(decision, probe, plate, omega, tolerance,
                    bool(resolved.get("wing", {}).get("enabled", False)))
    if BUILTIN_LINK_MODELS[decision.model].rigid and Tolerance.of(resolved).wants_flexible(
            "crank"):
        decision.model = FFRF
        decision.reason += ("; fidelity.quantities asks the crank's own deflection, which a "
                            "rigid crank gives as a prediction only: flexible")
    if not BUILTIN_LINK_MODELS[decision.model].rigid:
        if lumped:
            raise SceneError(f'crank.model = "auto": the criterion says the crank is '
                             f"flexible ({decision.reason}); a flexible crank is meshed "
                             f'from a plate: set crank.geometry = "plate" (and its '
                             f'thickness_m, width_m, material), or crank.model = "{RIGID}" '
                             f"to accept the error")
        if resolved["drive"]["kind"] != "spring":
            raise SceneError(f'crank.model = "auto": the criterion says the crank is '
                             f"flexible ({decision.reason}), but a flexible crank needs "
                             f'drive.kind = "spring"; set crank.model = "{RIGID}" to accept '
                             f"the error")
        _mode_cut(decision, resolved, "crank", k_phys, delta_t_s, calibration)
    decision.reason += ("; crank law from "
                        + (Path(crank_criterion.source).name or "(in memory)"))
    crank["model"] = decision.model
    return decision


def _crank_by_loads(decision: FidelityDecision, probe: dict[str, np.ndarray],
                    plate: Mapping[str, Any], omega_rad_per_s: float, tolerance: float,
                    wing: bool) -> None:
    """The crank's rigid deflection error (midpoint / L1) predicted from the probe's loads
    (:func:`flex.fidelity.predictor.predict_deflection`, the crank's in-mechanism
    ``omega_rad_per_s``; ``plate``: its plate or equivalent plate), in place.

    Without a wing it decides, as the coupler's (:func:`_decide_by_loads`): there the
    deflection is the governing error, and the prediction met the FFRF crank's within
    0.89-1.23 (11 scenes, docs/criterion.md). With a wing welded at A it is only stored: the
    prediction still meets the deflection (1.02-1.11, 4 scenes), but the crank-angle error
    governs, about 3 x the deflection error (the wing, turning with the crank's end at A,
    lags the chord), so predicted / measured governing error is 0.33-0.35, outside [0.67, 2],
    and the crank's n-law decides.
    """
    predicted = predict_deflection(probe, plate, "crank",
                                   omega_rad_per_s=omega_rad_per_s).relative_error(
                                       plate["length_m"])
    if not wing:
        _decide_by_loads(decision, predicted, tolerance)
        return
    decision.predicted_rigid_error = predicted
    decision.reason += (f"; the rigid run's loads predict a deflection of "
                        f"{predicted:.3g} of the crank's length (stored, not deciding: with the "
                        f"wing the crank-angle error governs, about 3 x the deflection's)")
