"""The mannequin: its topology, geometry, joints, traces, skin record: checks and JSON (floor 3: geometry, measure).

- clean: relabel axes, symmetrize central parts, register to the world frame (Section 2.3.4)
- field_checks: what a mannequin file's fields may hold (target measurements, section heights); short reprs
- joints: the joint centres: the JSON section, checks against the topology, following a deformation
- model: ``Mannequin``: a topology with geometry arrays, validation, JSON files
- skeleton: SMPL's 24 joints, the bone each part rides on, other rigs' joint names
- skin_record: how its skin was made (the file's versioned ``skin`` section), checked on load
- topology: ``Part`` and ``Topology``: the named parts and their rules (sides, twins, girths, cushion pairs)
- traces: what each part was traced from (mesh, vertices, fit settings)
"""
