"""The geometrically exact planar beam as a link model's behaviour (points 4-8 of the
contract in :mod:`flex.dynamics.link_models`): its section prepared from the plate, its
elements added between the link's joints, their section forces and energies sensed, the
flexible link's datasets plus the beam's own section forces and stresses
(:mod:`flex.bodies.exact_beam`), its cost per step and its solver settings."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from flex.base.physics import Plate
from flex.config.ladder import EXACT_BEAM_RUNG, FFRF_MOTION_ERROR_FRACTION
from flex.data.fields import AUTO
from flex.data.plates import EXACT_BEAM_ELEMENTS
from flex.data.results import Dataset
from flex.data.scene import Scene
from flex.dynamics.link_outputs import flexible_datasets, flexible_sensors, sensor_data

# ------------------------------------------------------------------------------------------
# exact beam: a planar geometrically exact (Simo-Reissner) beam of the plate
# ------------------------------------------------------------------------------------------
#: an exact beam's Newton stops on its *increment* (Exudyn ``newton.residualMode = 1``) at this
#: fraction of the run's ``newton_relative_tolerance`` (1e-12 at the default 1e-8; a looser
#: tolerance, a retry's or a noise floor's companion, loosens it alike). On its residual it
#: could not: the residual's round-off floor grows with the elements' axial stiffness (1e-8
#: stalled at 32 elements, 1e-6 at 128 on the 3 mm plate, 4e-6 was needed at 256), and what
#: that loose stop left moved the motion without order: the 1 mm plate's 256-element crank
#: angle history changed by 2.9e-6 rad from 5 to 2.5 us and by 1.6e-5 rad from 2.5 to 1.25 us,
#: its deployment time by 5.8e-9 then 5.5e-8 s. On the increment at 1e-12 the same runs
#: change by 2.1e-7 then 5.0e-8 rad (order 2.1) and 5.2e-10 then 1.5e-10 s, for 25 % more
#: iterations; the 3 and 10 mm plates at 64 elements show order 2 too (session 14,
#: ``/tmp/s14/reflev.py``)
EXACT_BEAM_INCREMENT_FRACTION = 1e-4


#: wall time per step [s] of an exact beam link: (per link, per element). CPU time of a
#: whole run (build, sensors, collection) per step, 10 ms of the thesis deployment at
#: h = 1e-5 s, sparse LU, modified Newton: 16 elements 0.22 ms, 32: 0.30, 64: 0.51, 128: 1.13
#: (a dense LU: 0.25, 0.48, 1.21, 3.40 ms, the same deflections to all digits)
STEP_COST_EXACT_BEAM_S = (1e-4, 8e-6)


def beam_elements(link: str, values: dict[str, Any]) -> int:
    if values["elements"] == AUTO:
        raise ValueError(f'{link}: resolve its "auto" elements first '
                         "(flex.fidelity.auto.resolve, flex.config.settings.resolve_link_keys)")
    return int(values["elements"])


def prepare_beam(scene: Scene, link: str, given: Any, cache_dir: Path | None) -> Any:
    """The link's :class:`flex.bodies.exact_beam.ExactBeamSection`, calibrated against the
    plate's converged 3-D reference (:func:`calibrated_section`; ``given``: one built)."""
    if given is not None:
        return given
    c = scene[link]
    beam_elements(link, c)
    return calibrated_section(Plate.of(c), cache_dir)


def beam_calibration_of(plate: Plate, cache_dir: Path | None) -> Any:
    """The exact beam's calibration for ``plate`` (:func:`flex.bodies.beam_calibration.
    beam_calibration` on :func:`flex.bodies.plate_reference.plate_reference`, whose entry is
    read from or kept in ``cache_dir``: seconds cold, milliseconds warm)."""
    from flex.bodies.beam_calibration import beam_calibration
    from flex.bodies.plate_reference import plate_reference

    return beam_calibration(plate_reference(plate, cache_dir=cache_dir))


def calibrated_section(plate: Plate, cache_dir: Path | None) -> Any:
    """The plate's beam section with its bending stiffness calibrated on the 3-D plate's
    section-mean deflection (the reference notes: E I_eff / E I = 1.00118 at 1 mm, 1.00092 at
    3 mm), the calibration kept with it (``calibration``)."""
    from flex.bodies.exact_beam import exact_beam_section

    calibration = beam_calibration_of(plate, cache_dir)
    return replace(calibration.section(exact_beam_section(plate)),
                   calibration=calibration.attrs())


def _calibrated_own(values: Mapping[str, Any], cache_dir: Path | None = None) -> float:
    return float(beam_calibration_of(Plate.of(values), cache_dir).idealization)


def _calibrated_bound(values: Mapping[str, Any], load_ratio: float,
                      cache_dir: Path | None = None) -> float:
    return _calibrated_own(values, cache_dir)


#: the exact beam calibrated per plate (:func:`calibrated_section`): its model error against
#: the 3-D plate measured on that plate's converged reference, not bounded by 0.05 t / L
CALIBRATED_BEAM_RUNG = replace(
    EXACT_BEAM_RUNG, name="exact beam (calibrated)", bound=_calibrated_bound,
    own_fraction=_calibrated_own,
    measured_by="the exact beam calibrated on the plate's p-converged 3-D reference "
    "(flex.bodies.plate_reference): its idealization measured per plate (the calibration "
    "factor's error and the calibrated frequency's residual) of a link's own deflection and "
    f"stress, {FFRF_MOTION_ERROR_FRACTION:g} of what the elasticity changes in the motion "
    "(the FFRF body's measured fraction, not measured for the beam)",
    leaves_out="the calibrated exact beam's nonlinear anticlastic stiffening of the {links} "
    "(~0.2 % x beta^2, beta = w^2 kappa / t: 0.0008 % at a deflection of 0.5 % of the length, "
    "0.012 % at 2 %; the reference notes) and the joints as pins at the section centres")


def add_exact_beam(builder: Any, link: str, section: Any) -> dict[str, Any]:
    """The beam from B to C (a coupler) or from A to B (a crank), moving as the rigid link
    at t = 0; its handles (its end markers are the link's joint markers)."""
    from flex.bodies.exact_beam import add_exact_beam_link

    init, elements = builder.init, beam_elements(link, builder.scene[link])
    section = section if section is not None else prepare_beam(builder.scene, link, None,
                                                                None)
    if link == "crank":
        beam = add_exact_beam_link(builder.mbs, section, elements, (0.0, 0.0),
                                   init.crank_angle_rad, (0.0, 0.0), init.crank_speed_rad_per_s)
    else:
        beam = add_exact_beam_link(
            builder.mbs, section, elements, init.joint_B_m, init.coupler_angle_rad,
            init.joint_B_velocity_m_per_s, init.coupler_speed_rad_per_s)
    return dict(beam.handles(), section=section,
                joint_markers=(beam.marker_start, beam.marker_end))


def _link_handles(mech: Any, link: str) -> dict[str, Any]:
    return mech.crank if link == "crank" else mech.coupler


def exact_beam_sensors(builder: Any, link: str, handles: dict[str, Any]) -> None:
    """Each element's section forces (axial and shear force, bending moment) and energies
    (kinetic, strain: summed by :mod:`flex.dynamics.collect`); a crank's joint-marker
    velocities (its chord's turning rate) and every flexible link's midpoint marker."""
    flexible_sensors(builder, link, handles)
    for index, element in enumerate(handles["elements"]):
        for output in ("ForceLocal", "TorqueLocal"):
            builder.add(f"{link}.element_{index}.{output}",
                        builder.sensor("Body", output, bodyNumber=element))
    builder.mech.flexible_energy[link] = tuple(
        [builder.mbs.AddSensor(builder.sensor("Body", kind, bodyNumber=element))
         for element in handles["elements"]] for kind in ("KineticEnergy", "PotentialEnergy"))


def exact_beam_datasets(mech: Any, link: str, time_s: np.ndarray) -> dict[str, Dataset]:
    """The flexible coupler's datasets (chord angle, midpoint; a crank's are read with its
    motion) and the beam's own section forces and stresses
    (:func:`flex.bodies.exact_beam.section_datasets`)."""
    from flex.base.channel import channel_filter, channel_text
    from flex.bodies.exact_beam import section_datasets

    out = flexible_datasets(mech, link, time_s)
    handles = _link_handles(mech, link)
    count = len(handles["elements"])
    force = np.stack([sensor_data(mech, f"{link}.element_{i}.ForceLocal")[:, 1:3]
                      for i in range(count)], axis=1)  # sample, element, (N, Q)
    moment = np.stack([sensor_data(mech, f"{link}.element_{i}.TorqueLocal")[:, 3]
                       for i in range(count)], axis=1)
    cutoff_Hz = mech.channel_cutoff_Hz
    out.update(section_datasets(link, handles["section"], force, moment,
                                channel_filter(time_s, cutoff_Hz),
                                "" if cutoff_Hz is None else channel_text(cutoff_Hz)))
    return out


def _elements(values: dict[str, Any]) -> int:
    """A beam link's element count (its ``"auto"``: :data:`EXACT_BEAM_ELEMENTS`)."""
    return int(values["elements"] if values["elements"] != AUTO else EXACT_BEAM_ELEMENTS)


def exact_beam_step_cost_s(values: dict[str, Any], modes: int | None) -> float:
    return STEP_COST_EXACT_BEAM_S[0] + STEP_COST_EXACT_BEAM_S[1] * float(_elements(values))


def exact_beam_newton_tolerances(relative_tolerance: float) -> float:
    """The tolerance an exact beam's Newton stops at, on its increment (relative and
    absolute): :data:`EXACT_BEAM_INCREMENT_FRACTION` of the run's residual
    ``relative_tolerance`` [-]."""
    return EXACT_BEAM_INCREMENT_FRACTION * relative_tolerance


def exact_beam_solver(settings: dict[str, Any], values: dict[str, Any]) -> None:
    """A sparse solver, and Newton stopping on its increment
    (:func:`exact_beam_newton_tolerances`), once however many beam links the scene has."""
    settings["linear_solver"] = "EigenSparse"
    if settings.get("newton_on_increment"):  # a second beam link: already set
        return
    settings["newton_on_increment"] = True
    tolerance = exact_beam_newton_tolerances(settings["newton_relative_tolerance"])
    settings["newton_relative_tolerance"] = settings["newton_absolute_tolerance"] = tolerance


__all__ = ["CALIBRATED_BEAM_RUNG", "EXACT_BEAM_INCREMENT_FRACTION",
           "STEP_COST_EXACT_BEAM_S", "beam_calibration_of", "calibrated_section",
           "add_exact_beam", "beam_elements", "exact_beam_datasets", "exact_beam_newton_tolerances",
           "exact_beam_sensors", "exact_beam_solver", "exact_beam_step_cost_s", "prepare_beam"]
