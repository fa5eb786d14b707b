"""Damping of a reduced (FFRF) body's elastic coordinates, by model (``<link>.damping_model``).

- ``"stiffness_proportional"`` (flex's default, :func:`flex.bodies.reduction.add_ffrf_link`):
  Rayleigh ``beta K`` with ``beta`` giving the first pinned-pinned bending mode
  ``damping_ratio`` of critical damping; higher modes are damped proportionally more.
- ``"modal_bands"`` (:func:`modal_band_damping_matrix`): every mode of the reduced body gets
  the damping ratio of its frequency band (:func:`band_damping_ratio`): 1 % below 100 Hz,
  10 % from 100 Hz to 1 kHz, 100 % (critical) above. This is the default modal damping of the
  commercial flexible-body codes: Adams Solver's FLEX_BODY statement without CRATIO
  applies "1% to modes under 100 Hz, 10% to modes under 1 kHz, full critical damping to
  modes over 1 kHz" (MSC Adams Solver documentation, FLEX_BODY); Altair MotionSolve's
  flexible bodies offer the same as their "Default Damping" (HyperWorks help, Deformable
  Body - Modes); RecurDyn is said to do the same (not checked here). Offered so that a flex
  run can be set up as an engineer would set it up in those codes. The thesis's scene stays
  undamped, as the thesis is.

The modal damping matrix is ``D = M Phi diag(2 zeta_i omega_i) Phi^T M`` with ``Phi`` the
mass-normalized eigenvectors of the reduced ``(K, M)`` (``Phi^T M Phi = I``), so that
``Phi^T D Phi = diag(2 zeta_i omega_i)``: each mode of the reduced body is damped on its own,
none is coupled to another. Modes with ``omega_i = 0`` (rigid-body content of the basis,
if any) get no damping.
"""

from __future__ import annotations

import numpy as np

from flex.base.errors import SceneError

#: ``"modal_bands"`` (module doc: the commercial codes' default): below LOW_BAND_HZ the low
#: ratio, up to and including HIGH_BAND_HZ the middle one, above it critical damping
LOW_BAND_HZ, HIGH_BAND_HZ = 100.0, 1000.0
BAND_RATIOS = (0.01, 0.10, 1.0)
#: the damping models of a reduced body, as ``<link>.damping_model`` names them
DAMPING_MODELS = ("stiffness_proportional", "modal_bands")


def band_damping_ratio(frequency_Hz: float) -> float:
    """The damping ratio of a mode of ``frequency_Hz`` [Hz] under the bands (below 100 Hz:
    0.01; up to 1 kHz: 0.10; above: 1.0)."""
    if frequency_Hz < LOW_BAND_HZ:
        return BAND_RATIOS[0]
    return BAND_RATIOS[1] if frequency_Hz <= HIGH_BAND_HZ else BAND_RATIOS[2]


def modal_band_damping_matrix(mass: np.ndarray, stiffness: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The band damping matrix of a reduced body (module doc) from its reduced mass and
    stiffness matrices [kg, N/m in the reduced coordinates' units]. Returns ``(D, frequencies
    [Hz], damping ratios)``, one frequency and ratio per mode, lowest first. SceneError when
    the mass matrix is not positive definite (no modes to damp)."""
    mass = 0.5 * (np.asarray(mass, dtype=float) + np.asarray(mass, dtype=float).T)
    stiffness = 0.5 * (np.asarray(stiffness, dtype=float)
                       + np.asarray(stiffness, dtype=float).T)
    import scipy.linalg  # ~75 ms: only where a body has band damping

    try:
        eigenvalues, shapes = scipy.linalg.eigh(stiffness, mass)  # Phi^T M Phi = I
    except np.linalg.LinAlgError:
        raise SceneError("damping_model = \"modal_bands\": the reduced mass matrix is not "
                         "positive definite (no modes to damp); use damping_model = "
                         "\"stiffness_proportional\"") from None
    omegas = np.sqrt(np.clip(eigenvalues, 0.0, None))
    frequencies_Hz = omegas / (2.0 * np.pi)
    ratios = np.array([band_damping_ratio(f) if omega > 0 else 0.0
                       for f, omega in zip(frequencies_Hz, omegas, strict=True)])
    weighted = mass @ shapes
    damping = weighted @ np.diag(2.0 * ratios * omegas) @ weighted.T
    return 0.5 * (damping + damping.T), frequencies_Hz, ratios


__all__ = ["BAND_RATIOS", "DAMPING_MODELS", "HIGH_BAND_HZ", "LOW_BAND_HZ", "band_damping_ratio",
           "modal_band_damping_matrix"]
