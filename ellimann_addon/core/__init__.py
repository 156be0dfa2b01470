"""ElliMann's core: numpy and the standard library only (no bpy, bmesh or mathutils).

Shared modules, then one package per domain; a package imports the shared modules and packages on lower floors
only (tests/core/test_layering.py):

- constants: measurements, reference ranges, section heights, plausibility limits, the paper's tables
- errors: ElliMannError and the errors naming a file, part or field; an error as one line
- files: atomic writes (core files and Blender's, ``atomic_output``), whole-file checks, stale temporaries
- option_table: ``Option`` and ``Choice``, the rows of each job's one table of options
- geometry (floor 1): ellipsoids, frames, meshes, cushions, volumes, the section hull
- measure (2): m_T, the extra measurements, measuring a body mesh
- mannequin (3): the model, its topology, fields' checks, traces, skeleton, joints, cleaning
- synthesis (4): request, options, IDW, refinement, reference sets, batches, populations
- pose (4): poses, standard poses, posed pieces, motion, retargeting, bones
- fitting (5): fitting ellipsoids and mannequins to bodies, building a reference set, reading body meshes
- formats (5): the format table and the files the core writes (JSON, MJCF, posed files, the .npz bundle)
- drape (6): garments, patterns, colliders (the pieces or the skin), fit metrics, drape settings
"""
