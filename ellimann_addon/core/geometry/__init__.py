"""Geometry: ellipsoids, frames and meshes in closed form, batched (floor 1: imports the core's shared modules only).

- cushion: cushions, the convex hull of two ellipsoids, as closed convex meshes; the 3-D convex hull of points
- ellipse_support: support functions of section ellipses in a plane; the drawn boundary of their hull
- ellipsoid: ellipsoids as frames and semi-axes: extents, sections at a height, bounds, distances
- elliptic: the incomplete elliptic integral of the second kind, from Carlson's R_F and R_D
- frames: SO(3): right-handed frames, sagittal mirroring, axis relabelling, rotation means, the nearest rotation
- mesh: triangle meshes: icospheres, volume, manifold and convexity checks, plane sections and their loops
- quaternion: unit quaternions <-> rotation matrices
- section_hull: the perimeter of the convex hull of a section's ellipses (Cauchy's formula, exact), m_T's girths
- volume: inside tests, grids, the cells a mannequin's pieces occupy, coverage and excess
"""
