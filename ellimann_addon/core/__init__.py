"""ElliMann's geometry core: numpy and the standard library only (no bpy, bmesh or mathutils).

Modules: ellipsoid (closed forms), frames (SO(3) operations), measure (m_T), cushion (hulls),
mesh (triangle-mesh helpers), mannequin (topology, geometry, JSON), errors, files.
"""
