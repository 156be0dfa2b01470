"""Posing: joint rotations, standard poses, posed pieces, motion and other rigs' clips (floor 4: mannequin and below).

- bones: the armature a bone-based rig needs for a mannequin's joints; exact limit boxes
- kinematics: ``Pose``: local joint rotations, forward kinematics, limits, inverse and mirrored poses
- motion: a drape's motion: from rest into a pose or a loop, frame by frame
- posed_pieces: a whole mannequin posed, cushions included (split at their joints)
- retarget: another rig's motion onto the SMPL joints
- standard: the standard poses and the walk cycle, from a mannequin's own joints
"""
