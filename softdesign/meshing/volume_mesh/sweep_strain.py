"""The 3D strain and stress of the swept mesh between q = 0 and q, with where the extremes sit.

Every node of :mod:`softdesign.meshing.volume_mesh.sweep_body` is one material point at
every q, so :mod:`softdesign.continuum.kinematic_stress` gives each
tetrahedron's strain from its nodes at q = 0 and at q.  The traction-free
direction of the stress is the normal of the surfaces of constant depth
(``t = sqrt(x^2 + y^2)`` of the reference disk: the skin, and the chamber's
wall, are such surfaces): ``G^-T grad t`` with G the map from the parameter
domain to the body at q = 0.

Where
    section (the link, counted from 1 at the base as actuation.csv and
    ``simulate --section`` count it), l, angle (rad, of the reference point
    about the centerline from N) and depth: 0 at the skin, 1 at the axis of a
    solid body or at the chamber's wall of a hollow one, of the tetrahedron's
    centroid.
Skin
    The in-plane principal stretches at the centre of each skin quad (two
    layers by two angles) from the central differences of its corners at
    q = 0 and at q (:func:`softdesign.fitting.strain.principal_stretches` on
    the metrics): what the feasibility stage measures from the surface's
    derivatives, on the mesh's nodes, to second order in their spacing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.continuum.kinematic_stress import ElementStrain, element_strain, rest_inverses
from softdesign.continuum.laws import HyperelasticLaw
from softdesign.fitting.strain import principal_stretches
from softdesign.meshing.volume_mesh.sweep_body import SweepReference
from softdesign.meshing.volume_mesh.sweep_mesh import SweptMesh
from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class Extreme:
    """A largest value and where: ``value`` at section (from 1 at the base), l, angle (rad), depth (0 skin .. 1
    axis or chamber)."""

    value: float
    section: int
    l: float
    angle: float
    depth: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, rounded to what the figures can tell."""
        return {"value": round(self.value, 6), "section": self.section, "l": round(self.l, 5),
                "angle_rad": round(self.angle, 5), "depth": round(self.depth, 4)}


def free_directions(mesh: SweptMesh, rest: FloatArray, inverses: FloatArray | None = None) -> FloatArray:
    """(T, 3) unit normals at q = 0 of the surfaces of constant depth through each tetrahedron (module notes);
    ``inverses``: :func:`~softdesign.continuum.kinematic_stress.rest_inverses` of ``rest``, when at hand."""
    param = mesh.reference_points()
    t = mesh.tets
    dp = (param[t[:, 1:]] - param[t[:, :1]]).transpose(0, 2, 1)
    dx_inverse = rest_inverses(rest, t) if inverses is None else inverses
    centroid = param[t].mean(axis=1)
    radial = np.column_stack([centroid[:, 0], centroid[:, 1], np.zeros(len(t))])
    norm = np.linalg.norm(radial, axis=1, keepdims=True)
    radial = np.where(norm > 1e-9, radial / np.maximum(norm, 1e-300), np.array([1.0, 0.0, 0.0]))
    # grad_x t = G^-T grad_p t with G = dx dp^-1, so G^-T = dx^-T dp^T
    normal = np.einsum("nji,nj->ni", dx_inverse, np.einsum("nji,nj->ni", dp, radial))
    return np.asarray(normal / np.linalg.norm(normal, axis=1, keepdims=True), np.float64)


def tet_places(mesh: SweptMesh, ref: SweepReference, link_of) -> tuple[IntArray, FloatArray, FloatArray, FloatArray]:
    """Section (link, from 1 at the base), l, angle and depth of every tetrahedron's centroid in the parameter
    domain (``link_of``: l -> the 0-based link, as the radius field's)."""
    centroid = mesh.reference_points()[mesh.tets].mean(axis=1)
    t = np.linalg.norm(centroid[:, :2], axis=1)
    inner = ref.chamber_radius
    depth = np.clip((1.0 - t) / (1.0 - inner), 0.0, 1.0)
    angle = np.mod(np.arctan2(centroid[:, 1], centroid[:, 0]), 2.0 * np.pi)
    return np.asarray(link_of(centroid[:, 2]), np.int64) + 1, centroid[:, 2], angle, depth


def extreme_of(values: FloatArray, places: tuple[IntArray, FloatArray, FloatArray, FloatArray]) -> Extreme:
    """The largest of ``values`` (T,) and its place (first of equals: deterministic)."""
    i = int(np.argmax(values))
    section, l, angle, depth = places
    return Extreme(float(values[i]), int(section[i]), float(l[i]), float(angle[i]), float(depth[i]))


def strain_at(mesh: SweptMesh, rest: FloatArray, moved: FloatArray, law: HyperelasticLaw | None,
              free: FloatArray, inverses: FloatArray | None = None) -> ElementStrain:
    """Every tetrahedron's strain (and stress, with a law) between ``rest`` (q = 0) and ``moved``;
    ``inverses`` (:func:`~softdesign.continuum.kinematic_stress.rest_inverses`) computed once for every q."""
    return element_strain(rest, moved, mesh.tets, law, free, inverses)


def skin_grid(mesh: SweptMesh) -> IntArray:
    """The skin's nodes (n, na): node of layer j at angle ``2 pi k / na`` (the cross-section's outer circle)."""
    na = mesh.section.outer_count
    grid = np.full((len(mesh.l), na), -1, np.int64)
    skin = mesh.node_point < na
    grid[mesh.node_layer[skin], mesh.node_point[skin]] = np.flatnonzero(skin)
    if np.any(grid < 0):
        raise ValueError("skin_grid: a layer lacks a node of the outer circle (a bug in the swept mesh)")
    return grid


def skin_places(mesh: SweptMesh) -> tuple[FloatArray, FloatArray]:
    """l (n - 1,) and angle (na,) rad of the centres of the skin's quads (between layers and angles)."""
    na = mesh.section.outer_count
    return 0.5 * (mesh.l[1:] + mesh.l[:-1]), 2.0 * np.pi * (np.arange(na) + 0.5) / na


def skin_stretches(mesh: SweptMesh, rest: FloatArray, moved: FloatArray) -> tuple[FloatArray, FloatArray]:
    """In-plane principal stretches (lambda1, lambda2) at the centre of every skin quad, each (n - 1, na).

    A quad's two tangents at its centre are the central differences of its corners (the mean of its two
    edges along l, and of its two along the angle), exact to second order in the quad's size, where one
    triangle's constant gradient is exact to first order only: on the demo at q = 1 they agree with the
    feasibility stage's metric at the quads' centres within 0.16 % away from the end cuts, the triangles
    within 3 %.  Places: :func:`skin_places`.
    """
    grid = skin_grid(mesh)

    def metric(x: FloatArray) -> FloatArray:
        corner = x[grid]
        turned = np.roll(corner, -1, axis=1)
        along = 0.5 * (corner[1:] + turned[1:] - corner[:-1] - turned[:-1])
        around = 0.5 * (turned[:-1] + turned[1:] - corner[:-1] - corner[1:])
        return np.stack([np.einsum("...k,...k->...", along, along), np.einsum("...k,...k->...", along, around),
                         np.einsum("...k,...k->...", around, around)], axis=-1)

    return principal_stretches(metric(rest), metric(moved))
