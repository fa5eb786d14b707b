"""The thesis's modal tables recomputed: Table 5 (four plate couplers, the rigid-or-flexible
number n = delta_t / T in both period conventions) and Tables 7 and 9 (ANSYS BEAM188 crank and
coupler frequencies) beside beam theory (:mod:`flex.experiments.thesis.beams`), the BEAM188
emulation
(:mod:`flex.experiments.thesis.beam_elements`) and 3D FE (:mod:`flex.experiments.thesis.fe_modes`).

Cavezza (2012), *Flexibility and Transient Dynamic Analysis of a Slider-Crank Deployment
Mechanism* (West Virginia University, MS thesis), sections 6.2-6.3; its published values are in
:mod:`flex.base.thesis`. SI units; the keys of the returned tables carry theirs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from flex.base import physics
from flex.base.errors import SceneError
from flex.base.physics import check_positive
from flex.base.thesis import (
    THESIS_COUPLER_LENGTH_M,
    THESIS_CRANK_LENGTH_M,
    THESIS_DELTA_T_S,
    THESIS_K,
    THESIS_K_COUPLER,
    THESIS_K_CRANK,
    THESIS_TABLE5,
    THESIS_TABLE5_WIDTH_M,
    THESIS_TABLE7_CRANK,
    THESIS_TABLE9_COUPLER,
)
from flex.experiments.thesis.beam_elements import beam_element_modes
from flex.experiments.thesis.beams import (
    THESIS_STEEL,
    Material,
    beam_link_modes,
    check_choice,
    euler_bernoulli_bending_rad_per_s,
    timoshenko_bending_rad_per_s,
)
from flex.experiments.thesis.fe_modes import PlateModes, plate_modes

DEPLOYMENT_TIME_S = THESIS_DELTA_T_S
"""Deployment time delta_t of the thesis's criterion, s
(:data:`flex.base.thesis.THESIS_DELTA_T_S`)."""

THESIS_K_CRITERION = int(THESIS_K)
"""Cavezza 2012, sec. 6.2: the k chosen for the criterion (model 1 of Table 5), 108."""


TABLE5_FE_MESH_SIZES_M: tuple[float, ...] = (0.002, 0.003, 0.0025, 0.0035)
"""Production netgen maxh (m) of the four Table 5 plates, t = 1, 3, 5, 10 mm, from
:func:`flex.experiments.thesis.mesh_convergence.mesh_convergence` (pinned-pinned, first in-plane
bending): each
lies within 0.05 % of the Richardson-extrapolated (or finest) frequency and costs at most
~10k DOF."""


def _periods_and_counts(prefix: str, omega_rad_per_s: np.ndarray, deployment_time_s: float,
                        criterion_k: float) -> dict[str, np.ndarray]:
    """Both period conventions for circular frequencies omega: the thesis's T = 1/omega and
    the physical T = 2 pi / omega; n = delta_t / T; verdict "rigid" if n > k (Eq. 64-65)."""
    period_thesis_s = 1.0 / omega_rad_per_s
    period_physical_s = 2.0 * math.pi / omega_rad_per_s
    n = physics.n_values(deployment_time_s, omega_rad_per_s)
    n_thesis, n_physical = n["thesis"], n["physical"]
    return {
        f"{prefix}_period_thesis_convention_s": period_thesis_s,
        f"{prefix}_period_physical_s": period_physical_s,
        f"{prefix}_n_thesis_convention": n_thesis,
        f"{prefix}_n_physical": n_physical,
        f"{prefix}_verdict_thesis_convention": np.where(n_thesis > criterion_k, "rigid",
                                                        "flexible"),
        f"{prefix}_verdict_physical": np.where(n_physical > criterion_k, "rigid", "flexible"),
    }


def _table5_published_columns(length_m: float, width_m: float) -> dict[str, np.ndarray]:
    """Table 5's plates (length and width [m], the thesis's thicknesses) and its published
    columns, one entry per model (:func:`thesis_table5_reproduction`)."""
    return {
        "model": THESIS_TABLE5["model"].copy(),
        "coupler_length_m": np.full(4, length_m),
        "coupler_width_m": np.full(4, width_m),
        "coupler_thickness_m": THESIS_TABLE5["coupler_thickness_m"].copy(),
        "thesis_frequency_as_published": THESIS_TABLE5["frequency_as_published"].copy(),
        "thesis_period_as_published_s": THESIS_TABLE5["period_as_published_s"].copy(),
        "thesis_n_as_published": THESIS_TABLE5["n_as_published"].copy(),
        "thesis_verdict_as_published": THESIS_TABLE5["verdict_as_published"].copy(),
    }


def thesis_table5_reproduction(mesh_sizes_m: Sequence[float] | None = TABLE5_FE_MESH_SIZES_M,
                               material: Material = THESIS_STEEL,
                               deployment_time_s: float = DEPLOYMENT_TIME_S,
                               criterion_k: float = THESIS_K_CRITERION,
                               fe_modes: Sequence[PlateModes] | None = None
                               ) -> dict[str, np.ndarray]:
    """Table 5 of Cavezza 2012 recomputed: four plate couplers 0.08 x 0.01 x t m.

    t = 1, 3, 5, 10 mm (bending height t in the mechanism plane, y), steel E = 200 GPa,
    rho = 7850 kg/m^3 (thesis) and nu = 0.3 (ours) unless ``material`` says otherwise. For
    each model: the first pinned-pinned in-plane bending circular frequency from
    Euler-Bernoulli (the thesis's "Frequency"), Timoshenko and 3D FE (:func:`plate_modes`,
    pinned-pinned, netgen maxh ``mesh_sizes_m[i]`` m; None skips the FE columns), then for
    Euler-Bernoulli and FE both period conventions and the counts n = delta_t / T with
    ``deployment_time_s`` (s), and the verdicts of the criterion with k = ``criterion_k``
    ("rigid" if n > k, Eq. 64-65). ``fe_modes``: the four plates' pinned-pinned FE modes of
    ``material`` when the caller has them already (the modal survey solves the same plates);
    one that is not that plate at that maxh is solved here, as are all with None.

    Returns a dict of numpy arrays, one entry per model (index 0..3), with units in the keys:
    ``model``, ``coupler_{length,width,thickness}_m``, ``thesis_frequency_as_published``,
    ``thesis_period_as_published_s``, ``thesis_n_as_published``,
    ``thesis_verdict_as_published``; ``euler_bernoulli_omega_rad_per_s``,
    ``euler_bernoulli_frequency_Hz``, ``timoshenko_omega_rad_per_s``,
    ``timoshenko_frequency_Hz``, ``euler_bernoulli_vs_thesis_relative``; ``fe_omega_rad_per_s``,
    ``fe_frequency_Hz``, ``fe_mesh_size_m``, ``fe_element_count``, ``fe_dof_count``,
    ``fe_vs_euler_bernoulli_relative``, ``fe_vs_timoshenko_relative``; for prefix
    ``euler_bernoulli`` and ``fe``: ``{prefix}_period_thesis_convention_s`` (1/omega),
    ``{prefix}_period_physical_s`` (2 pi/omega), ``{prefix}_n_thesis_convention``,
    ``{prefix}_n_physical``, ``{prefix}_verdict_thesis_convention``,
    ``{prefix}_verdict_physical``; and 0-d arrays ``deployment_time_s``, ``criterion_k``.
    Relative differences are (a - b) / b.
    """
    check_positive(deployment_time_s=deployment_time_s, criterion_k=criterion_k)
    thickness_m = THESIS_TABLE5["coupler_thickness_m"]
    length_m, width_m = THESIS_COUPLER_LENGTH_M, THESIS_TABLE5_WIDTH_M
    eb = np.array([euler_bernoulli_bending_rad_per_s(length_m, t, width_m, "pinned-pinned", 1,
                                                     material)[0] for t in thickness_m])
    timoshenko = np.array([timoshenko_bending_rad_per_s(length_m, t, width_m, "pinned-pinned",
                                                        1, material)[0] for t in thickness_m])
    table: dict[str, np.ndarray] = {
        **_table5_published_columns(length_m, width_m),
        "euler_bernoulli_omega_rad_per_s": eb,
        "euler_bernoulli_frequency_Hz": eb / (2 * math.pi),
        "timoshenko_omega_rad_per_s": timoshenko,
        "timoshenko_frequency_Hz": timoshenko / (2 * math.pi),
        "euler_bernoulli_vs_thesis_relative":
            eb / THESIS_TABLE5["frequency_as_published"] - 1.0,
    }
    table.update(_periods_and_counts("euler_bernoulli", eb, deployment_time_s, criterion_k))
    if mesh_sizes_m is not None:
        table.update(_table5_fe_columns(mesh_sizes_m, material, eb, timoshenko, fe_modes))
        table.update(_periods_and_counts("fe", table["fe_omega_rad_per_s"], deployment_time_s,
                                         criterion_k))
    table["deployment_time_s"] = np.array(deployment_time_s)
    table["criterion_k"] = np.array(criterion_k)
    return table


def _table5_fe_columns(mesh_sizes_m: Sequence[float], material: Material,
                       eb_rad_per_s: np.ndarray, timoshenko_rad_per_s: np.ndarray,
                       solved: Sequence[PlateModes] | None = None) -> dict[str, np.ndarray]:
    """The 3D FE columns of Table 5 (:func:`thesis_table5_reproduction`): first pinned-pinned
    in-plane bending of each plate at netgen maxh ``mesh_sizes_m`` (m, one per model);
    ``solved``: those solutions if the caller has them, else None."""
    sizes = np.asarray(mesh_sizes_m, dtype=float)
    if sizes.shape != (4,):
        raise SceneError("mesh_sizes_m: give four sizes (m), one per Table 5 model")
    fe, elements, dofs = [], [], []
    for index, (t, size_m) in enumerate(zip(THESIS_TABLE5["coupler_thickness_m"], sizes,
                                            strict=True)):
        modes = _given_modes(solved, index, float(t), float(size_m)) or plate_modes(
            THESIS_COUPLER_LENGTH_M, float(t), THESIS_TABLE5_WIDTH_M, float(size_m),
            "pinned-pinned", 5, material)
        fe.append(modes.frequencies_rad_per_s[modes.first_of_kind("in-plane bending")])
        elements.append(modes.element_count)
        dofs.append(modes.dof_count)
    fe_omega = np.array(fe)
    return {
        "fe_omega_rad_per_s": fe_omega,
        "fe_frequency_Hz": fe_omega / (2 * math.pi),
        "fe_mesh_size_m": sizes,
        "fe_element_count": np.array(elements),
        "fe_dof_count": np.array(dofs),
        "fe_vs_euler_bernoulli_relative": fe_omega / eb_rad_per_s - 1.0,
        "fe_vs_timoshenko_relative": fe_omega / timoshenko_rad_per_s - 1.0,
    }


def _given_modes(solved: Sequence[PlateModes] | None, index: int, thickness_m: float,
                 mesh_size_m: float) -> PlateModes | None:
    """``solved[index]`` if it is the Table 5 plate's of this thickness [m], pinned-pinned at
    this maxh [m], else None (a scene with another coupler length or width solved other
    plates)."""
    modes = None if solved is None else solved[index]
    if modes is None or (modes.boundary_condition, modes.length_m, modes.thickness_m,
                         modes.width_m, modes.mesh_size_m) != (
            "pinned-pinned", THESIS_COUPLER_LENGTH_M, thickness_m, THESIS_TABLE5_WIDTH_M,
            mesh_size_m):
        return None
    return modes


THESIS_ANSYS_SECTION_SIDE_M = 0.010
"""Our reading of the cross-section of the thesis's BEAM188 links (Tables 7 and 9): a solid
10 mm x 10 mm square (the thesis does not state it). See :func:`thesis_link_modal_reproduction`."""

THESIS_ANSYS_ELEMENT_COUNT = 8
"""Our reading of the BEAM188 mesh of Tables 7 and 9: 8 linear elements per link."""

THESIS_ANSYS_BOUNDARY_CONDITION = "pinned-roller"
"""Our reading of the supports of Tables 7 and 9: pin at one end, roller (axially free) at the
other, rotation about z free, out-of-plane rotations and twist held at both ends."""

THESIS_LINKS: tuple[str, ...] = ("crank", "coupler")
#: per link: its length [m], its published table (Table 7 or 9) and the thesis's k from it
_PUBLISHED = {"crank": (THESIS_CRANK_LENGTH_M, THESIS_TABLE7_CRANK, THESIS_K_CRANK),
              "coupler": (THESIS_COUPLER_LENGTH_M, THESIS_TABLE9_COUPLER, THESIS_K_COUPLER)}


def thesis_link_modal_reproduction(
        link: str, fe_mesh_size_m: float | None = None,
        section_side_m: float = THESIS_ANSYS_SECTION_SIDE_M,
        element_count: int = THESIS_ANSYS_ELEMENT_COUNT,
        boundary_condition: str = THESIS_ANSYS_BOUNDARY_CONDITION,
        material: Material = THESIS_STEEL,
        deployment_time_s: float = DEPLOYMENT_TIME_S) -> dict[str, np.ndarray]:
    """Tables 7 (crank) and 9 (coupler) of Cavezza 2012 next to our models of them.

    The thesis gives five BEAM188 "TIME/FREQ" values per link with no unit, section or
    supports. Our reading, found by fitting (rms 0.4 %, worst 0.7 % over all ten values with
    nothing tuned but the discrete choices): values in Hz (cyclic), a solid square section
    ``section_side_m`` = 10 mm (Table 5's model 3), ``element_count`` = 8 linear BEAM188
    elements per link, supports ``boundary_condition`` = "pinned-roller" (x free at the second
    end). The evidence: (1) the coupler's 4th value 15799 and the crank's 3rd 31598 are the
    fixed-free axial modes c / (4 L) = 15774 and 31547 Hz (c = sqrt(E / rho)), both +0.16 %,
    which is the consistent-mass error of 8 linear rod elements; (2) coupler 18215 and crank
    36431 differ by exactly 2 = L2 / L1, so they are rod (torsion) modes; the St-Venant torsion
    frequency of any square section is c_t sqrt(J / I_p) / (2 L) = 17968 Hz for the coupler at
    nu = 0.3, and the 8-element model gives 18084 (-0.7 % from the thesis); (3) the bending
    values follow from a 10 mm square with in-plane bending pinned and out-of-plane bending
    clamped. Read as rad/s, the axial modes would need a wave speed 2 pi too large.

    ``link``: "crank" (L1 = 0.04 m) or "coupler" (L2 = 0.08 m). ``fe_mesh_size_m``: netgen
    maxh (m) for a 3D FE column (:func:`plate_modes`, same supports), None to skip.
    ``deployment_time_s``: delta_t (s).

    Returns a dict of numpy arrays (per mode 1..5 unless 0-d): ``mode``,
    ``thesis_value_as_published``, ``thesis_period_as_published_s``, ``thesis_n_reading_Hz``
    (delta_t * value: T = 1/value, the thesis's convention, physical if the values are Hz),
    ``thesis_n_reading_rad_per_s`` (delta_t * value / (2 pi)); for each model prefix
    ``beam188_emulation`` (:func:`beam_element_modes`), ``timoshenko`` and
    ``euler_bernoulli`` (:func:`beam_link_modes`), and ``fe`` if requested:
    ``{prefix}_frequency_Hz``, ``{prefix}_kind``, ``{prefix}_vs_thesis_relative``
    ((model - thesis) / thesis, mode by mode), ``{prefix}_period_s`` (1 / f); 0-d:
    ``thesis_k_as_published`` (733 or 299, from the rounded 5th period),
    ``k_reading_Hz`` (delta_t * value_5), ``k_reading_rad_per_s`` (delta_t * value_5 / (2 pi)),
    ``{prefix}_k`` (delta_t * f_5), ``link_length_m``, ``section_side_m``, ``element_count``,
    ``boundary_condition``, ``deployment_time_s``.
    """
    check_choice("link", link, THESIS_LINKS)
    check_positive(section_side_m=section_side_m, deployment_time_s=deployment_time_s)
    length_m, published, thesis_k = _PUBLISHED[link]
    values = published["frequency_as_published"]
    table = _published_link_columns(published, thesis_k, deployment_time_s)
    models = _link_models(length_m, section_side_m, element_count, boundary_condition,
                          values.size, material)
    if fe_mesh_size_m is not None:
        models["fe"], fe_columns = _fe_link_model(length_m, section_side_m, fe_mesh_size_m,
                                                  boundary_condition, values.size, material)
        table.update(fe_columns)
    table.update(_link_model_columns(models, values, deployment_time_s))
    table.update(link_length_m=np.array(length_m), section_side_m=np.array(section_side_m),
                 element_count=np.array(element_count),
                 boundary_condition=np.array(boundary_condition),
                 deployment_time_s=np.array(deployment_time_s))
    return table


def _published_link_columns(published: dict[str, np.ndarray], thesis_k: float,
                            deployment_time_s: float) -> dict[str, np.ndarray]:
    """The thesis's columns of Table 7 or 9 (``published``, k as published ``thesis_k``) and
    the counts n and k they give read as Hz and as rad/s
    (:func:`thesis_link_modal_reproduction`)."""
    values = published["frequency_as_published"]
    return {
        "mode": published["mode"].copy(),
        "thesis_value_as_published": values.copy(),
        "thesis_period_as_published_s": published["period_as_published_s"].copy(),
        "thesis_n_reading_Hz": deployment_time_s * values,
        "thesis_n_reading_rad_per_s": physics.n_values(deployment_time_s,
                                                       values)["physical"],
        "thesis_k_as_published": np.array(thesis_k),
        "k_reading_Hz": np.array(deployment_time_s * values[-1]),
        "k_reading_rad_per_s": np.array(physics.n_values(deployment_time_s,
                                                         values[-1])["physical"]),
    }


def _fe_link_model(length_m: float, section_side_m: float, fe_mesh_size_m: float,
                   boundary_condition: str, mode_count: int, material: Material
                   ) -> tuple[tuple[np.ndarray, tuple[str, ...]], dict[str, np.ndarray]]:
    """The 3D FE column of a square-section link (:func:`plate_modes`, netgen maxh
    ``fe_mesh_size_m``): its frequencies [Hz] and mode kinds, and its columns
    ``fe_mesh_size_m`` and ``fe_dof_count``."""
    modes = plate_modes(length_m, section_side_m, section_side_m, fe_mesh_size_m,
                        boundary_condition, mode_count, material)
    return ((modes.frequencies_Hz, modes.mode_kinds),
            {"fe_mesh_size_m": np.array(fe_mesh_size_m),
             "fe_dof_count": np.array(modes.dof_count)})


def _link_model_columns(models: dict[str, tuple[np.ndarray, tuple[str, ...]]],
                        values: np.ndarray, deployment_time_s: float) -> dict[str, np.ndarray]:
    """Per model (prefix: frequencies [Hz], kinds) its columns beside the thesis's ``values``:
    frequency, kind, relative difference, period and k (:func:`thesis_link_modal_reproduction`)."""
    table = {}
    for prefix, (frequencies_Hz, kinds) in models.items():
        table[f"{prefix}_frequency_Hz"] = frequencies_Hz
        table[f"{prefix}_kind"] = np.array(kinds)
        table[f"{prefix}_vs_thesis_relative"] = frequencies_Hz / values - 1.0
        table[f"{prefix}_period_s"] = 1.0 / frequencies_Hz
        table[f"{prefix}_k"] = np.array(deployment_time_s * frequencies_Hz[-1])
    return table


def _link_models(length_m: float, section_side_m: float, element_count: int,
                 boundary_condition: str, mode_count: int, material: Material
                 ) -> dict[str, tuple[np.ndarray, tuple[str, ...]]]:
    """Frequencies [Hz] and mode kinds of a square-section link by the BEAM188 emulation
    (``beam188_emulation``), Timoshenko (``timoshenko``) and Euler-Bernoulli beams
    (``euler_bernoulli``); length and section side in m."""
    models: dict[str, tuple[np.ndarray, tuple[str, ...]]] = {}
    emulation = beam_element_modes(length_m, section_side_m, section_side_m,
                                   boundary_condition, element_count, mode_count, material)
    models["beam188_emulation"] = (emulation.frequencies_Hz, emulation.mode_kinds)
    for theory, prefix in (("timoshenko", "timoshenko"),
                           ("euler-bernoulli", "euler_bernoulli")):
        beam = beam_link_modes(length_m, section_side_m, section_side_m, boundary_condition,
                               mode_count, theory, material)
        models[prefix] = (beam.frequencies_Hz, beam.mode_kinds)
    return models
