"""Draping: garments cut from a mannequin's measurements, its colliders, fit metrics, settings (floor 6: everything
below, the skin among it).

- colliders: a mannequin's convex pieces, or its skin, as triangle meshes for a cloth solver
- fit_metrics: garment-to-body distances and the fit statistics of a drape
- garments: the garment list, the tube dress, ``make_garment``
- patterns: what garments are made of: ``Garment``, pattern sizes, body rings, clearance
- settings: ``DrapeSettings`` and ``DRAPE``, the table of their values, labels and descriptions
- t_shirt: the T-shirt garment
"""
