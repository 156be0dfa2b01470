"""ElliMann's geometry core: numpy and the standard library only (no bpy, bmesh or mathutils).

Modules:
- body_measure: measuring a body mesh (a scan): arms found by geometry, the five and the extra measurements
- clean: relabel axes, symmetrize central parts, register to the world frame (paper, Section 2.3.4)
- collision: a mannequin's convex collision pieces (cushions and ellipsoids as meshes)
- constants: measurements, reference ranges, section heights, plausibility limits, the paper's tables
- cushion: cushions, the convex hull of two ellipsoids (meshes, support points)
- ellipsoid: closed forms of ellipsoids (extents, sections at a height, bounds)
- errors: ElliMannError and the errors naming a file, part or field
- export_mjcf: MJCF (MuJoCo) export
- files: atomic writes (core files and Blender's, ``atomic_output``), whole-file checks, stale temporaries
- extra_measures: the measurements beyond the five (neck, upper arm, thigh, calf, crotch height, arm length) on a
  mannequin, in closed form, and their landmarks
- fit: fitting an ellipsoid to points (inscribed, moments, enclosing)
- garment_fit: garment-to-body distances and the fit statistics of a drape
- formats: the one table of output formats (extension, writer, needs Blender)
- frames: SO(3) operations (rotation means, mirroring, right-handed frames)
- garment_base: what garments are made of (Garment, pattern sizes, body rings, clear_of)
- garments: the garment list, the tube dress, make_garment, estimate_vertices
- idw: segmented and proportional IDW (weights, interpolation)
- mannequin: topology, geometry, JSON, plausibility checks
- measure: m_T (tailor measurements, closed form), the m_T line
- mesh: triangle-mesh helpers (icospheres, normals, plane sections and their loops, boundary edges)
- options: SynthesisOptions and DrapeSettings, with the one table of their values, labels and descriptions
- quaternion: quaternion <-> rotation matrix
- reference_set: the Reference Mannequins (loading, caching, what IDW and refinement precompute)
- refine: exact mode, the refinement until m_T matches the request
- refine_extra: exact mode for the extra measurements (a degree of freedom each), synthesize_extra
- request: a synthesis request checked, its name, the relative error of m_T
- synthesis: synthesize / synthesize_batch, putting request, reference set, IDW and refinement together
- t_shirt: the T-shirt garment
- writers: JSON and MJCF files by extension (no Blender)
"""
