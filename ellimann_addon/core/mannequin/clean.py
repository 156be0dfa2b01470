"""Cleaning of mannequins (paper, Section 2.3.4): registration, symmetry and consistent axis labels."""

import numpy as np

from ..errors import MannequinError, Problem
from ..geometry.ellipsoid import axis_extent
from ..geometry.frames import mirror_frame, relabel_to_reference, symmetrize_central
from .joints import mirror_joints
from .topology import NAME_PATTERN

REGISTRATION_LABEL = "Trapezius"


def landmark_indices(topology, label=REGISTRATION_LABEL):
    """Indices of the parts whose label (name without number and side) is ``label``."""
    found = [
        i for i, name in enumerate(topology.names) if (m := NAME_PATTERN.match(name)) and m.group("label") == label
    ]
    if not found:
        raise MannequinError([Problem("", "topology", f"has no '{label}' ellipsoids to register on")])
    return np.array(found)


def registration_offset(mannequin, label=REGISTRATION_LABEL):
    """Translation that registers a mannequin to the world frame.

    z: lowest point of the body to 0; y: centroid of the landmark ellipsoids (the paper's
    lateral-view trapezius centroid) to 0; x: their midpoint (between the shoulders) to 0.
    """
    idx = landmark_indices(mannequin.topology, label)
    lowest = np.min(mannequin.center[:, 2] - axis_extent(mannequin.rotation, mannequin.semi_axes, 2))
    centroid = mannequin.center[idx].mean(axis=0)
    return -np.array([centroid[0], centroid[1], lowest])


def register_to_world(mannequin, label=REGISTRATION_LABEL):
    return mannequin.translated(registration_offset(mannequin, label))


def mirror_side(mannequin, source="L", replace=True):
    """Replace the other side's ellipsoids by sagittal mirrors of ``source``'s (right-handed frames)."""
    topology = mannequin.topology
    src = topology.indices(source)
    dst = topology.twin_indices[src]
    rotation, center = mirror_frame(mannequin.rotation[src], mannequin.center[src])
    out = mannequin.copy()
    if replace:
        out.rotation[dst], out.center[dst], out.semi_axes[dst] = rotation, center, mannequin.semi_axes[src]
        if out.joints is not None:
            out.joints = mirror_joints(out.joints, source)
    return out


def symmetrize(mannequin, source="L"):
    """Mirror ``source`` onto the other side and make every central ellipsoid symmetric about x = 0."""
    out = mirror_side(mannequin, source)
    central = out.topology.indices("C")
    if len(central):
        out.rotation[central], out.center[central] = symmetrize_central(out.rotation[central], out.center[central])
    return out


def relabel(mannequin, reference):
    """Relabel and invert every ellipsoid's axes to agree with the same ellipsoid of ``reference``."""
    reference = reference if reference.topology == mannequin.topology else reference.reordered(mannequin.topology)
    rotation, semi_axes, _ = relabel_to_reference(mannequin.rotation, mannequin.semi_axes, reference.rotation)
    return mannequin.copy(rotation=rotation, semi_axes=semi_axes)


def clean(mannequins, reference_index=0, source="L"):
    """The paper's cleaning of a set of mannequins sharing one topology.

    Registers each (so the sagittal plane is x = 0), makes each symmetric (``source`` side
    mirrored, central ellipsoids symmetrized), registers again (mirroring can move the lowest point
    and the landmarks' centroid), then relabels every ellipsoid's axes against the reference
    mannequin's. Relabelling changes no ellipsoid as a set, so symmetry and registration are kept.
    """
    cleaned = [register_to_world(symmetrize(register_to_world(m), source)) for m in mannequins]
    reference = cleaned[reference_index]
    return [m if i == reference_index else relabel(m, reference) for i, m in enumerate(cleaned)]


def asymmetry(mannequin):
    """Largest deviation (m) of any ellipsoid from its mirror twin's mirror image (0 if symmetric).

    Compares the ellipsoids as sets through their shape matrices and centres, so axis labelling
    does not matter.
    """
    from ..geometry.ellipsoid import shape_matrix

    twin = mannequin.topology.twin_indices
    flip = np.diag([-1.0, 1.0, 1.0])
    shape = shape_matrix(mannequin.rotation, mannequin.semi_axes)
    mirrored_shape = flip @ shape[twin] @ flip
    mirrored_center = mannequin.center[twin] * np.array([-1.0, 1.0, 1.0])
    center_error = np.linalg.norm(mannequin.center - mirrored_center, axis=1)
    shape_error = np.sqrt(np.abs(shape - mirrored_shape).max(axis=(1, 2)))
    return float(max(center_error.max(), shape_error.max()))
