"""Finite-element check of a helical spring's peak shear stress (NGsolve): a few turns of
the wire as a curved-tetrahedron helix, the stress at its mid section against Shigley's
closed forms (:mod:`flex.bodies.spring`)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from flex.base.errors import SceneError
from flex.base.physics import lame_first_parameter_Pa
from flex.bodies.spring import (
    MUSIC_WIRE_YOUNGS_MODULUS_PA,
    SpringDesign,
    bergstrasser_factor,
    nominal_torsional_shear_stress_Pa,
    require_positive,
    wahl_factor,
)


@dataclass(frozen=True)
class HelixSegmentStress:
    """Result of :func:`fe_helix_segment_stress`; stresses in Pa, rate in N/m.

    ``inner_fibre_*`` are at the inner fibre (closest to the spring axis) of the mid-section;
    ``peak_max_shear_Pa`` is the largest max shear (Tresca, (s1 - s3)/2) on the mid-section's
    perimeter, at ``peak_angle_deg`` from the inner fibre. ``fe_rate_N_per_m`` is the segment's
    axial compliance scaled to the design's active coils.
    """

    force_N: float
    segment_turns: float
    element_order: int
    mesh_size_m: float
    elements: int
    degrees_of_freedom: int
    inner_fibre_max_shear_Pa: float
    inner_fibre_von_mises_Pa: float
    peak_max_shear_Pa: float
    peak_angle_deg: float
    wahl_shear_stress_Pa: float
    bergstrasser_shear_stress_Pa: float
    nominal_shear_stress_Pa: float
    fe_rate_N_per_m: float
    analytic_rate_N_per_m: float
    wall_time_s: float

    @property
    def fe_over_wahl(self) -> float:
        """FE peak max shear over the Wahl-corrected stress [-]."""
        return self.peak_max_shear_Pa / self.wahl_shear_stress_Pa

    @property
    def fe_over_bergstrasser(self) -> float:
        return self.peak_max_shear_Pa / self.bergstrasser_shear_stress_Pa


def fe_helix_segment_stress(design: SpringDesign, force_N: float, *,
                            segment_turns: float = 0.125, mesh_size_m: float | None = None,
                            element_order: int = 3,
                            youngs_modulus_Pa: float = MUSIC_WIRE_YOUNGS_MODULUS_PA,
                            sample_points: int = 72) -> HelixSegmentStress:
    """Peak shear stress of ``design`` under the axial force ``force_N`` [N] by linear FE.

    What it models: a segment of ``segment_turns`` turns of the real helix (mean radius D/2,
    the design's pitch) with a circular wire section, built by sweeping a circle along an OCC
    helix (a line on a cylinder) and meshed with curved tetrahedra of ``element_order``
    (default cubic, maxh ``mesh_size_m``, default d/2), linear isotropic elasticity with
    E = ``youngs_modulus_Pa`` and the design's G (Poisson ratio E/(2G) - 1). One end face is
    clamped; on the other a traction statically equivalent to F along the spring axis acting
    on the axis (uniform shear F/A plus the torsion and the small bending of F's moment about
    the section centroid, distributed as in a straight bar). By Saint-Venant the
    mid-section, ``segment_turns``/2 turns from both ends, then carries exactly the coil's
    section resultants: torque F D/2 cos(alpha), shear F cos(alpha) and the pitch terms.
    The stress is sampled on the mid-section's perimeter (at 0.999 of the wire radius, inside
    the curved mesh). Contact between coils and the end coils are not modelled.

    The rate check uses the axial displacement of the load point on the axis (mean
    displacement plus mean rotation of the loaded face), scaled from the segment to the
    design's active coils. At the defaults (~1.5k cubic tetrahedra, 27k DOF) it runs in ~1.5 s on
    an idle 2-core machine (netgen's mesh generation dominates; 4-9 s were measured under load).
    netgen refines by the wire's curvature, so ``mesh_size_m`` above ~d/4 changes little.
    """
    f_axial, turns, e_mod, maxh, poisson = _checked_inputs(
        design, force_N, segment_turns, mesh_size_m, element_order, youngs_modulus_Pa,
        sample_points)
    d = design.wire_diameter_m
    start = time.perf_counter()
    mesh = _helix_segment_mesh(design, turns, maxh, element_order)
    space, stress_cf, fe_rate = _solve_helix_segment(mesh, design, f_axial, turns, e_mod,
                                                     poisson, element_order)
    samples = _mid_section_samples(mesh, stress_cf, design, turns, sample_points)
    peak = max(samples, key=lambda s: s[1])
    nominal = nominal_torsional_shear_stress_Pa(f_axial, design.mean_coil_diameter_m, d)
    c = design.spring_index
    return HelixSegmentStress(
        force_N=f_axial, segment_turns=turns, element_order=element_order, mesh_size_m=maxh,
        elements=mesh.ne, degrees_of_freedom=space.ndof,
        inner_fibre_max_shear_Pa=samples[0][1], inner_fibre_von_mises_Pa=samples[0][2],
        peak_max_shear_Pa=peak[1], peak_angle_deg=peak[0],
        wahl_shear_stress_Pa=wahl_factor(c) * nominal,
        bergstrasser_shear_stress_Pa=bergstrasser_factor(c) * nominal,
        nominal_shear_stress_Pa=nominal, fe_rate_N_per_m=fe_rate,
        analytic_rate_N_per_m=design.rate_N_per_m,
        wall_time_s=time.perf_counter() - start)


def _checked_inputs(design: SpringDesign, force_N: float, segment_turns: float,
                    mesh_size_m: float | None, element_order: int, youngs_modulus_Pa: float,
                    sample_points: int) -> tuple[float, float, float, float, float]:
    """:func:`fe_helix_segment_stress`'s inputs checked (a :class:`SceneError` names the
    first bad one): force [N], turns, E [Pa], maxh [m] (default d/2) and Poisson ratio."""
    f_axial = require_positive("force_N", force_N, "N")
    turns = require_positive("segment_turns", segment_turns, "turns")
    if turns > 1.0:
        raise SceneError(f"spring segment_turns = {segment_turns!r}: must be in (0, 1] turns")
    e_mod = require_positive("youngs_modulus_Pa", youngs_modulus_Pa, "Pa")
    if element_order not in (2, 3, 4):
        raise SceneError(f"spring element_order = {element_order!r}: must be 2, 3 or 4")
    if not (isinstance(sample_points, int) and sample_points >= 4):
        raise SceneError(f"spring sample_points = {sample_points!r}: must be an integer >= 4")
    radius_wire = design.wire_diameter_m / 2.0
    maxh = radius_wire if mesh_size_m is None else require_positive("mesh_size_m",
                                                                    mesh_size_m, "m")
    poisson = e_mod / (2.0 * design.shear_modulus_Pa) - 1.0
    if not -1.0 < poisson < 0.5:
        raise SceneError(f"spring youngs_modulus_Pa = {youngs_modulus_Pa!r}: with G = "
                         f"{design.shear_modulus_Pa:g} Pa the Poisson ratio {poisson:.3f} "
                         "must lie in (-1, 0.5), i.e. 2G < E < 3G")
    return f_axial, turns, e_mod, maxh, poisson


def _helix_frame(design: SpringDesign, angle_rad: float):
    """Centre [m], unit tangent and outward radial unit vector of the coil's centre line
    at the helix angle ``angle_rad`` (spring axis z, first end at angle 0, z = 0)."""
    import numpy as np

    coil_radius = design.mean_coil_diameter_m / 2.0
    pitch = design.pitch_m
    centre = np.array([coil_radius * math.cos(angle_rad), coil_radius * math.sin(angle_rad),
                       pitch * angle_rad / (2.0 * math.pi)])
    tangent = np.array([-coil_radius * math.sin(angle_rad),
                        coil_radius * math.cos(angle_rad), pitch / (2.0 * math.pi)])
    tangent /= np.linalg.norm(tangent)
    radial_out = np.array([math.cos(angle_rad), math.sin(angle_rad), 0.0])
    return centre, tangent, radial_out


def _helix_segment_mesh(design: SpringDesign, turns: float, maxh: float, element_order: int):
    """NGsolve mesh (curved to ``element_order``, netgen maxh [m]) of ``turns`` turns of the
    wire, its end faces named ``clamped`` (z = 0) and ``loaded``."""
    import ngsolve as ngs
    from netgen.occ import (
        Circle,
        Cylinder,
        Edge,
        Face,
        OCCGeometry,
        Pipe,
        Pnt,
        Segment,
        Wire,
        Z,
        gp_Pnt2d,
    )

    radius_wire = design.wire_diameter_m / 2.0
    height_end = design.pitch_m * turns
    # Helix = straight line in the (angle, height) parameter plane of a cylinder's face.
    cylinder = Cylinder(Pnt(0.0, 0.0, 0.0), Z, r=design.mean_coil_diameter_m / 2.0, h=1.0)
    helix = Edge(Segment(gp_Pnt2d(0.0, 0.0), gp_Pnt2d(2.0 * math.pi * turns, height_end)),
                 cylinder.faces[0])
    section = Face(Wire([Circle(helix.start, helix.Tangent(0.0), radius_wire)]))
    wire_solid = Pipe(Wire([helix]), section)
    for face in wire_solid.faces:
        centre = face.center
        if face.mass < 2.0 * math.pi * radius_wire**2:
            face.name = "clamped" if abs(centre.z) < 0.5 * height_end + 1e-12 else "loaded"
    # serially: the same mesh as netgen's parallel meshing without its spinning threads
    # (flex.bodies.plate.plate_mesh)
    mesh = ngs.Mesh(OCCGeometry(wire_solid).GenerateMesh(maxh=maxh, parallel_meshing=False))
    mesh.Curve(element_order)
    if not {"clamped", "loaded"} <= set(mesh.GetBoundaries()):
        raise SceneError("spring FE: could not identify the helix segment's end faces")
    return mesh


def _solve_helix_segment(mesh, design: SpringDesign, f_axial: float, turns: float,
                         e_mod: float, poisson: float, element_order: int):
    """Linear elastic solution of the clamped segment under the axial force ``f_axial`` [N]
    acting on the spring axis (as a traction on the loaded face): the FE space, the stress
    field [Pa] and the rate [N/m] scaled from the segment to the design's active coils."""
    import ngsolve as ngs
    import numpy as np

    d = design.wire_diameter_m
    area = math.pi * (d / 2.0)**2
    second_moment = math.pi * d**4 / 64.0
    polar_moment = 2.0 * second_moment
    centre_end, normal_end, _ = _helix_frame(design, 2.0 * math.pi * turns)
    force = np.array([0.0, 0.0, f_axial])
    axis_point = np.array([0.0, 0.0, design.pitch_m * turns])
    moment = np.cross(axis_point - centre_end, force)
    moment_torsion = moment.dot(normal_end) * normal_end
    moment_bending = moment - moment_torsion

    def vec(a) -> ngs.CoefficientFunction:
        return ngs.CF(tuple(float(v) for v in a))

    rho = ngs.CF((ngs.x, ngs.y, ngs.z)) - vec(centre_end)
    traction = (vec(force / area) + ngs.Cross(vec(moment_torsion), rho) / polar_moment
                + vec(normal_end) * ngs.InnerProduct(vec(np.cross(normal_end, moment_bending)),
                                                     rho) / second_moment)
    shear_mod = design.shear_modulus_Pa
    lame_lambda = lame_first_parameter_Pa(e_mod, poisson)

    def strain(w):
        return ngs.Sym(ngs.Grad(w))

    def stress(w):
        return 2.0 * shear_mod * strain(w) + lame_lambda * ngs.Trace(strain(w)) * ngs.Id(3)

    space = ngs.VectorH1(mesh, order=element_order, dirichlet="clamped")
    trial, test = space.TnT()
    stiffness = ngs.BilinearForm(ngs.InnerProduct(stress(trial), strain(test)) * ngs.dx,
                                 symmetric=True)
    load = ngs.LinearForm(traction * test * ngs.ds("loaded"))
    displacement = ngs.GridFunction(space)
    with ngs.TaskManager():
        stiffness.Assemble()
        load.Assemble()
        solver = stiffness.mat.Inverse(space.FreeDofs(), inverse="sparsecholesky")
        displacement.vec.data = solver * load.vec
        # Load point on the axis: mean displacement + mean rotation x (axis - centroid).
        loaded = ngs.ds("loaded")
        mean_u = np.array([ngs.Integrate(displacement[i] * loaded, mesh) for i in range(3)])
        mean_u /= ngs.Integrate(ngs.CF(1.0) * loaded, mesh)
        rotation_moment = ngs.Cross(rho, displacement)
        m_rot = np.array([ngs.Integrate(rotation_moment[i] * loaded, mesh) for i in range(3)])
    # For a circular face: integral of rho x (theta x rho) = I (Id + n n^T) theta.
    rotation = (m_rot - 0.5 * normal_end * normal_end.dot(m_rot)) / second_moment
    axial_deflection = (mean_u + np.cross(rotation, axis_point - centre_end))[2]
    fe_rate = f_axial / axial_deflection * turns / design.active_coils
    return space, stress(displacement), fe_rate


def _mid_section_samples(mesh, stress_cf, design: SpringDesign, turns: float,
                         sample_points: int) -> list[tuple[float, float, float]]:
    """``(angle from the inner fibre [deg], max shear [Pa], von Mises [Pa])`` at
    ``sample_points`` points of the mid-section's perimeter (0.999 of the wire radius);
    points just outside the curved mesh are skipped, the inner fibre must be found."""
    import numpy as np

    radius_wire = design.wire_diameter_m / 2.0
    centre_mid, tangent_mid, radial_mid = _helix_frame(design, 2.0 * math.pi * turns / 2.0)
    binormal = np.cross(tangent_mid, radial_mid)
    samples = []
    for angle in np.linspace(0.0, 2.0 * math.pi, sample_points, endpoint=False):
        direction = -math.cos(angle) * radial_mid + math.sin(angle) * binormal  # 0: inner
        point = centre_mid + 0.999 * radius_wire * direction
        try:
            tensor = np.array(stress_cf(mesh(*point))).reshape(3, 3)
        except Exception:  # a point just outside the curved mesh: skip it
            continue
        principal = np.linalg.eigvalsh(0.5 * (tensor + tensor.T))
        max_shear = 0.5 * (principal[-1] - principal[0])
        von_mises = math.sqrt(0.5 * ((principal[0] - principal[1])**2
                                     + (principal[1] - principal[2])**2
                                     + (principal[2] - principal[0])**2))
        samples.append((math.degrees(angle), max_shear, von_mises))
    if not samples or samples[0][0] != 0.0:
        raise SceneError("spring FE: the inner-fibre sample point fell outside the mesh; "
                         "refine mesh_size_m")
    return samples
