"""Fitting: ellipsoids and mannequins fitted to body meshes, and reference sets built so (floor 5).

- body_mesh: ``BodyMesh``: reading OBJ bodies, closedness, vertex areas and normals
- inscribed: one ellipsoid inside a body mesh (a frame from a vertex selection, the maximal ellipsoid that fills)
- mannequin_fit: every part of a mannequin fitted inside one body from its recorded vertices
- point_fit: an ellipsoid fitted to points (inscribed, moments, enclosing): Fit Ellipsoid's
- reference_bodies: what a built set keeps of its bodies: the bodies file and, from ten bodies, their body space
- reference_build: ``build_reference_set``: fit, register, symmetrize, refine, clean and check N bodies
- reference_extend: ``extend_reference_set``: bodies added to a set already built, the RMs there untouched
"""
