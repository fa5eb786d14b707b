"""The exact beam's per-plate calibration from a converged 3D reference.

A plate strip with free long edges bends with E (not E / (1 - nu^2)), but its section does not
stay straight across the width (anticlastic curl) and its width stiffens it slightly: compared
on the section mean (:mod:`flex.bodies.plate_reference`), the 3D plate is stiffer than the
Timoshenko beam of :func:`flex.bodies.exact_beam.exact_beam_section` (E, kappa = 5/6) by about
0.1 % at w / L = 1/8. One factor on the bending stiffness, EI_eff / EI, chosen so that the
beam's static mid-span deflection under the reference's uniform load equals the 3D section
mean (pinned-pinned, :func:`flex.base.physics.pinned_timoshenko_midpoint_deflection_m`),
calibrates the beam; its first pinned-pinned frequency
(:func:`flex.base.physics.timoshenko_pinned_pinned_omega`, shear and rotary inertia, rho I
unchanged) against the 3D one is the independent check.

The factor's error comes from the reference's deflection error (first order). The beam
consumes it as the section of :meth:`BeamCalibration.section`: the same section with
``bending_stiffness_Nm2`` scaled (axial and shear stiffness, mass and rotary inertia as they
are).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Any

from flex.base.physics import (
    SHEAR_CORRECTION_RECTANGLE,
    pinned_timoshenko_midpoint_deflection_m,
    timoshenko_pinned_pinned_omega,
)
from flex.bodies.exact_beam import ExactBeamSection, exact_beam_section
from flex.bodies.plate_reference import PlateReference


@dataclass(frozen=True)
class BeamCalibration:
    """The exact beam's bending-stiffness factor for one plate and its checks (module doc).

    ``bending_stiffness_factor`` EI_eff / EI [-] with its error; the deflections [m] along the
    reference's load ``line_load_N_per_m`` [N/m]: 3D section mean, the uncalibrated beam's
    and its shear part; the first pinned-pinned bending frequencies [Hz]: 3D, uncalibrated
    and calibrated beam. ``shear_correction``: the beam's kappa."""

    bending_stiffness_factor: float
    bending_stiffness_factor_error: float
    line_load_N_per_m: float
    reference_deflection_m: float
    beam_deflection_m: float
    beam_shear_deflection_m: float
    reference_first_bending_Hz: float
    reference_first_bending_error_Hz: float
    beam_first_bending_Hz: float
    calibrated_first_bending_Hz: float
    shear_correction: float

    @property
    def frequency_relative_difference(self) -> float:
        """Calibrated beam's first bending frequency / the 3D one - 1 [-]."""
        return self.calibrated_first_bending_Hz / self.reference_first_bending_Hz - 1.0

    @property
    def uncalibrated_frequency_relative_difference(self) -> float:
        """Uncalibrated beam's first bending frequency / the 3D one - 1 [-]."""
        return self.beam_first_bending_Hz / self.reference_first_bending_Hz - 1.0

    @property
    def frequency_relative_uncertainty(self) -> float:
        """What the frequency check cannot resolve [-]: the 3D frequency's relative error
        plus half the factor's (a frequency goes with the square root of a stiffness)."""
        return (self.reference_first_bending_error_Hz / self.reference_first_bending_Hz
                + 0.5 * self.bending_stiffness_factor_error / self.bending_stiffness_factor)

    @property
    def idealization(self) -> float:
        """What the calibrated beam may still differ from the 3-D plate by, relative to its
        deflection [-]: the factor's error, plus twice the larger of the calibrated
        frequency's residual and what that check cannot resolve (a stiffness goes with the
        square of a frequency). Linear: the anticlastic stiffening of large deflections
        (~0.2 % beta^2, the reference notes) is not in it."""
        return (self.bending_stiffness_factor_error / self.bending_stiffness_factor
                + 2.0 * max(abs(self.frequency_relative_difference),
                            self.frequency_relative_uncertainty))

    @property
    def shear_share(self) -> float:
        """Shear part of the uncalibrated beam's deflection [-]."""
        return self.beam_shear_deflection_m / self.beam_deflection_m

    def section(self, section: ExactBeamSection) -> ExactBeamSection:
        """``section`` (the plate's, :func:`flex.bodies.exact_beam.exact_beam_section`) with
        its bending stiffness E I scaled by the factor; nothing else changed."""
        return replace(section, bending_stiffness_Nm2=section.bending_stiffness_Nm2
                       * self.bending_stiffness_factor)

    def attrs(self) -> dict[str, Any]:
        """The calibration as HDF5 attributes (units in the names)."""
        values = asdict(self)
        values.update(frequency_relative_difference=self.frequency_relative_difference,
                      uncalibrated_frequency_relative_difference=(
                          self.uncalibrated_frequency_relative_difference),
                      frequency_relative_uncertainty=self.frequency_relative_uncertainty,
                      shear_share=self.shear_share, idealization=self.idealization)
        return values


def beam_calibration(reference: PlateReference,
                     shear_correction: float = SHEAR_CORRECTION_RECTANGLE
                     ) -> BeamCalibration:
    """The factor EI_eff / EI that puts the pinned-pinned Timoshenko beam of the reference's
    plate (E, ``shear_correction`` kappa) on the 3D section-mean deflection under the same
    uniform load, its error and the frequency check (module doc)."""
    section = exact_beam_section(reference.plate, shear_correction)
    load, length_m = reference.line_load_N_per_m, section.length_m
    bending_stiffness = section.bending_stiffness_Nm2
    beam = float(pinned_timoshenko_midpoint_deflection_m(load, length_m, bending_stiffness,
                                                         section.shear_stiffness_N))
    shear = beam - float(pinned_timoshenko_midpoint_deflection_m(load, length_m,
                                                                 bending_stiffness, math.inf))
    target = reference.section_mean_deflection_m
    if not target > shear:
        raise ValueError(f"3D deflection {target!r} m is not above the beam's shear part "
                         f"{shear!r} m: no bending stiffness matches it")
    factor = (beam - shear) / (target - shear)
    factor_error = factor * reference.section_mean_deflection_error_m / (target - shear)

    def first_bending_Hz(stiffness_Nm2: float) -> float:
        omega = timoshenko_pinned_pinned_omega(1, length_m, stiffness_Nm2,
                                               section.shear_stiffness_N,
                                               section.mass_per_length_kg_per_m,
                                               section.rotary_inertia_kg_m)
        return float(omega) / (2.0 * math.pi)

    return BeamCalibration(
        factor, factor_error, load, target, beam, shear, reference.first_bending_Hz,
        reference.first_bending_error_Hz, first_bending_Hz(bending_stiffness),
        first_bending_Hz(factor * bending_stiffness), shear_correction)
