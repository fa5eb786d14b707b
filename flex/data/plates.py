"""Plates that will be meshed: what makes sense as a meshed link, what this machine can mesh
(:class:`MeshEstimate`, before any meshing), and a link's mass properties.

Split from :mod:`flex.data.scene` (which re-exports these names); whether a link's model
meshes its plate is the caller's (the link model's ``meshed`` flag, :mod:`flex.data.scene`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from flex.base.errors import SceneError
from flex.base.physics import Plate
from flex.base.progress import duration_text

Scene = dict[str, dict[str, Any]]
#: the beam elements of a beam link (``<link>.elements``, the geometrically exact beam
#: coupler) by default and for ``"auto"``: fixed, not chosen by tolerance. Measured on the
#: bundled deployment with the 1 mm coupler (h = 1e-5 s) against the nonlinear FE coupler
#: (the reference rung, 10.6 min): first crest of the midpoint deflection -1.06 / -0.07 /
#: +0.08 % at 16 / 32 / 64 elements, peak deflection -0.70 / -0.52 / +0.19 %, at 0.6, 1.1
#: and 2.0 s CPU a run: 16 would spend the default 1 % tolerance on the elements alone
EXACT_BEAM_ELEMENTS = 32

# ------------------------------------------------------------------------------------------
# meshed plates: what makes sense, and what this machine can mesh
# ------------------------------------------------------------------------------------------
#: largest mesh_size_m / min(thickness_m, width_m) of a meshed plate. Quadratic tetrahedra
#: bend well with one element across the thickness while the elements are not much longer
#: than thick: measured first pinned-pinned bending frequency against Euler-Bernoulli
#: (80 x 10 mm steel plates): ratio 2 (1 mm, 2 mm elements) +0.08 %; ratio 20: +1.8 %
#: (0.1 mm, 2 mm) and +6.4 % (0.3 mm, 6 mm: also only 13 elements along the length); ratio
#: 50: +13 %; ratio 100: +14 %; ratio 200: +20 %. The studies mesh at ratios 2-20.
MESH_ASPECT_LIMIT = 20.0
#: largest length_m / thickness_m of a meshed plate link (smallest thickness: L / 1000).
#: Slenderness L / r = 3464 (r = t / sqrt(12)): Euler buckling at pi^2 E / (L/r)^2 =
#: 8e-7 E, e.g. 0.16 MPa in steel; such a strip is a foil that buckles under any load the
#: mechanism carries, not a link the linear FFRF body (or a solid mesh) describes. The studies
#: reach L / t = 267 (0.3 mm coupler).
PLATE_SLENDERNESS_LIMIT = 1000.0
#: smallest length_m / thickness_m of a meshed plate link: the rigid joint faces disturb
#: the plate over about one thickness from each end (Saint-Venant), so below 2 no part of the
#: link is free of them: its midpoint deflection and bending stress (evaluated away from
#: the end faces, one thickness from each) would mean nothing. The studies reach 4 (20 mm).
PLATE_STUBBINESS_LIMIT = 2.0
#: largest estimated memory of a plate reduction (or nonlinear FE body) [bytes]: two thirds
#: of this machine's 24 GiB, the rest for the simulation, the operating system and the
#: other process of a 2-core run (about 870k DOF by :func:`estimate_mesh`, ~30 min to build).
MESH_MEMORY_LIMIT_BYTES = 16 * 2**30


@dataclass(frozen=True)
class MeshEstimate:
    """Estimated size and cost of meshing and reducing one plate (before any meshing).

    Calibrated on netgen meshes of steel plates 80 mm long (second-order tetrahedra, as
    :mod:`flex.bodies.reduction` builds them), one process, 2-core machine:

    ==========================  ========  =======  ======  ===========  =========
    t x w, maxh [mm]            elements  DOF      est.    build [s]    peak RSS
    ==========================  ========  =======  ======  ===========  =========
    1 x 10, 2                   1463      9627     10.7k   2.6          0.24 GB
    1 x 10, 1                   5711      35805    42.9k   13.7         0.50 GB
    1 x 10, 0.5                 23403     143670   177k    77.5         1.56 GB
    3 x 10, 0.7                 36065     175212   194k    154          2.07 GB
    2 x 10, 0.3 (mesh only)     333045    --       --      23 (mesh)    --
    1 x 100, 2 (mesh only)      13895     --       --      2.3 (mesh)   --
    ==========================  ========  =======  ======  ===========  =========

    Elements: ``max(5.6 V / h^3, 3.65 S / h^2)`` (V volume, S surface area, h = maxh):
    netgen fills a plate thicker than h with ~5.6 elements per h^3 and meshes a thinner one
    from its two large faces (~3.65 elements per h^2 of surface), within +-25 % on the
    meshes above (1.5x high on the 1 mm, 0.5 mm mesh). Nodes of the quadratic mesh: 2.2
    per element when the surface term dominates, 1.65 when the volume does; DOF = 3 x
    nodes. Memory: 0.15 GB + 11.5 kB per DOF, the sparse factorisation's share growing as
    DOF^(1/3) beyond the largest mesh measured (175k DOF); build time: 154 s x (DOF /
    175k)^1.5 (Craig-Bampton eigenmodes dominate). Estimates: within a factor 2 of what a
    build takes.
    """

    elements: float
    dof: float
    memory_bytes: float
    build_time_s: float

    def text(self) -> str:
        """One-line description, e.g. ``~1.5e+03 elements, ~1.1e+04 DOF, ~0.26 GiB, ~2 s``."""
        return (f"~{self.elements:.2g} quadratic tetrahedra, ~{self.dof:.2g} DOF, "
                f"~{self.memory_bytes / 2**30:.2g} GiB, ~{duration_text(self.build_time_s)} to "
                f"mesh and reduce")


#: the Craig-Bampton modes the build times of :class:`MeshEstimate` were measured with
ESTIMATE_MODES = 6


def modes_cost_factor(modes: int) -> float:
    """Build time of a reduction to ``modes`` in-plane modes relative to one to
    :data:`ESTIMATE_MODES`: the eigen-solve computes about 2 x modes + 4 eigenmodes (more
    when the in-plane ones are not all among them) and its orthogonalisation grows with
    their square. Measured on a 1 mm plate, 2 mm mesh (9.6k DOF, one process on a 2-core
    machine loaded by others): 7.6 / 20 / 53 / 216 s at 2 / 6 / 24 / 40 modes;
    ``1 + 0.3 m + 4e-4 m^3`` follows those ratios within a factor 1.5."""
    def grow(count: float) -> float:
        return 1.0 + 0.3 * count + 4e-4 * count**3

    return grow(float(modes)) / grow(ESTIMATE_MODES)


def estimate_mesh(length_m: float, thickness_m: float, width_m: float,
                  mesh_size_m: float, modes: int | None = None) -> MeshEstimate:
    """Elements, DOF, memory and build time of a plate mesh before meshing (see
    :class:`MeshEstimate` for the calibration); ``modes``: the reduction's mode count,
    which scales the build time (:func:`modes_cost_factor`; None: the calibration's).
    Pure arithmetic: never meshes."""
    h = mesh_size_m
    volume = length_m * thickness_m * width_m
    surface = 2.0 * (length_m * thickness_m + length_m * width_m + thickness_m * width_m)
    from_volume, from_surface = 5.6 * volume / h**3, 3.65 * surface / h**2
    elements = max(from_volume, from_surface, 6.0)
    nodes = elements * (2.2 if from_surface >= from_volume else 1.65)
    dof = 3.0 * nodes
    memory = 0.15e9 + 11.5e3 * dof * max(1.0, dof / 175e3) ** (1.0 / 3.0)
    build = 154.0 * (dof / 175e3) ** 1.5
    if modes is not None:
        build *= modes_cost_factor(modes)
    return MeshEstimate(elements, dof, memory, build)


def meshed_plate(link: str, values: dict[str, Any], meshed: bool
                 ) -> tuple[float, str, str] | None:
    """Whether the scene meshes ``link``'s plate: ``(thickness_m meshed, its name, why)`` or
    None. ``meshed``: whether the link's (concrete) model meshes its plate (its entry's
    ``meshed`` flag; ignored for ``"auto"``).

    A meshed model's link is meshed (``ffrf``, nonlinear FE); an ``auto`` crank always is (its
    frequency is computed on the mesh; a lumped crank as the plate of its mass, of thickness
    mass / (density x length x width), as :func:`flex.fidelity.auto.equivalent_crank_plate`); an
    ``auto`` coupler is when the criterion chooses ``ffrf``.
    """
    model = values["model"]
    name = f"{link}.thickness_m"
    if model != "auto":
        return (values["thickness_m"], name, f'{link}.model = "{model}"') if meshed else None
    if link == "crank" and values["geometry"] == "lumped":
        from flex.base.physics import plate_thickness_for_mass_m

        thickness = plate_thickness_for_mass_m(values["mass_kg"], values["length_m"],
                                               values["width_m"], values["density_kg_per_m3"])
        return (thickness, "the thickness of the plate of crank.mass_kg (mass / (density_kg_"
                "per_m3 x length_m x width_m))", 'crank.model = "auto" meshes a lumped crank '
                "as the plate of its mass")
    if link == "crank":
        return values["thickness_m"], name, 'crank.model = "auto" meshes the crank plate'
    return (values["thickness_m"], name,
            'coupler.model = "auto" meshes the plate if it chooses "ffrf"')


def check_meshed_plate(link: str, values: dict[str, Any], meshed: bool) -> None:
    """Refuse a plate that will be meshed but cannot mean anything, or that this machine
    cannot mesh (the estimate is in the message); nothing is meshed here. ``meshed``: whether
    the link's model meshes its plate (:func:`meshed_plate`)."""
    found = meshed_plate(link, values, meshed)
    if found is None:
        return
    thickness, name, why = found
    length, width, mesh = values["length_m"], values["width_m"], values["mesh_size_m"]

    def as_mass(relation: str, bound: float) -> str:  # a lumped auto crank: on its mass_kg
        if values["geometry"] != "lumped":
            return ""
        mass = bound * values["density_kg_per_m3"] * length * width
        return (f"; i.e. {link}.mass_kg {relation} {mass:g} kg at its density_kg_per_m3, "
                f"length_m and width_m")

    for word, ratio, relation, outside, meaning in (
            ("least", PLATE_SLENDERNESS_LIMIT, ">=", -1,
             "thinner, it is a foil that buckles under any load the mechanism carries"),
            ("most", PLATE_STUBBINESS_LIMIT, "<=", 1,
             "thicker, the rigid joint faces reach its midpoint (Saint-Venant) and its "
             "deflection and stress mean nothing")):
        bound = length / ratio
        if outside * (thickness - bound * (1 + outside * 1e-9)) > 0:
            raise SceneError(f"{name} = {thickness:g}: a meshed plate link must be at "
                             f"{word} {link}.length_m / {ratio:g} = {bound:g} m thick "
                             f"({why}){as_mass(relation, bound)}; {meaning}")
    if mesh == "auto":  # checked once resolved (flex.fidelity.auto.check)
        return
    if mesh > length * (1 + 1e-9):
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} must be <= {link}.length_m = "
                         f"{length:g} ({why}); about 1-2 x thickness_m is accurate")
    smallest = min(thickness, width)
    limit = MESH_ASPECT_LIMIT * smallest
    if mesh > limit * (1 + 1e-9):
        side = name if thickness <= width else f"{link}.width_m"
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} must be <= {MESH_ASPECT_LIMIT:g} x "
                         f"{side} = {limit:g} ({why}): longer elements than that make "
                         f"the plate too stiff in bending (+13 % at 50 x); about 1-2 x "
                         f"thickness is accurate")
    estimate = estimate_mesh(length, thickness, width, mesh)
    if estimate.memory_bytes > MESH_MEMORY_LIMIT_BYTES:
        raise SceneError(f"{link}.mesh_size_m = {mesh:g} on a {length:g} x {thickness:g} x "
                         f"{width:g} m plate needs {estimate.text()} (estimate); this machine "
                         f"takes at most {MESH_MEMORY_LIMIT_BYTES / 2**30:g} GiB ({why}): use "
                         f"a coarser mesh_size_m or a smaller plate")


def plate_mass_properties(scene: Scene, link: str = "coupler") -> tuple[float, float]:
    """Mass [kg] and in-plane inertia about the centre of mass [kg m^2] of a link.

    ``link`` is ``"coupler"`` or ``"crank"``. Lumped geometry returns the scene's
    ``mass_kg`` and ``inertia_kgm2``; plate geometry computes them from length x thickness x
    width and density (a cuboid: m (L^2 + t^2)/12).
    """
    values = scene[link]
    if values["geometry"] == "lumped":
        return values["mass_kg"], values["inertia_kgm2"]
    plate = Plate.of(values)
    return plate.mass_kg, plate.inertia_kgm2


def check_damping_model(link: str, values: dict[str, Any], entry: Any) -> None:
    """Refuse ``<link>.damping_model = "modal_bands"`` where nothing would read it or it
    would be ignored: with a model that is not a modal (FFRF) reduction (``entry``: its
    registry entry, None for ``"auto"``, whose fitted laws know damping ratios only) or with
    a ``damping_ratio`` (the bands set every ratio)."""
    if values.get("damping_model", "stiffness_proportional") != "modal_bands":
        return
    if entry is None:
        raise SceneError(f'{link}.damping_model = "modal_bands" with {link}.model = "auto": '
                         "auto decides with laws fitted per damping ratio; set "
                         f'{link}.model = "ffrf" or damping_model = "stiffness_proportional"')
    if "modes" not in entry.knobs:
        raise SceneError(f'{link}.damping_model = "modal_bands" damps the modes of a reduced '
                         f'(FFRF) body; {link}.model = "{values["model"]}" has none: set '
                         f'{link}.model = "ffrf" or damping_model = "stiffness_proportional"')
    if values["damping_ratio"] != 0:
        raise SceneError(f"{link}.damping_ratio = {values['damping_ratio']:g} with "
                         f'damping_model = "modal_bands": the bands set every mode\'s ratio, '
                         "this one would be ignored; accepted: 0")


def is_damped(values: dict[str, Any]) -> bool:
    """Whether a link's keys damp its elastic motion: a ``damping_ratio`` above 0 or the
    ``"modal_bands"`` damping model (a reference without damping, the nonlinear FE body,
    cannot stand in for it)."""
    return values["damping_ratio"] > 0 or values.get("damping_model") == "modal_bands"


def check_beam_plate(link: str, scene: Scene) -> None:
    """A beam model of ``link`` (its registry entry's own check): the beam is the plate's, so
    ``<link>.geometry`` must be ``"plate"`` (a lumped link has no section). A beam crank's
    nodes are planar: the coupler must be the same beam model (a 3D coupler's tilt is held by
    a revolute joint at B on a crank that has a frame), and no wing is welded to it (the weld
    needs a frame at A)."""
    values, model = scene[link], scene[link]["model"]
    if values["geometry"] != "plate":
        raise SceneError(f'{link}.model = "{model}" needs {link}.geometry = "plate" '
                         "(the beam's section is the plate's thickness_m x width_m)")
    if link != "crank":
        return
    if scene["coupler"]["model"] != model:
        raise SceneError(f'crank.model = "{model}" needs coupler.model = "{model}" (its planar '
                         "nodes hold no 3D coupler's tilt at B); accepted: "
                         f'coupler.model = "{model}"')
    if scene["wing"]["enabled"]:
        raise SceneError(f'crank.model = "{model}" carries no wing (the weld at A needs a '
                         "frame its planar nodes do not have); accepted: wing.enabled = false")
