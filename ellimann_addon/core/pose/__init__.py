"""Posing: joint rotations, standard poses, posed pieces, motion and other rigs' clips (floor 4: mannequin and below).

- bone_match: which clip bone drives which joint: listed rigs' names, else names, sides and the chain
- bones: the armature a bone-based rig needs for a mannequin's joints; exact limit boxes
- clip: a clip on a mannequin: retargeted, clamped, the clamps per joint, the feet against the floor
- kinematics: ``Pose``: local joint rotations, forward kinematics, limits, inverse and mirrored poses
- motion: a drape's motion: from rest into a pose or a loop, frame by frame
- posed_pieces: a whole mannequin posed, cushions included (split at their joints)
- retarget: another rig's motion onto the SMPL joints (direction by direction, hinges bent about their axes)
- rig_names: the rigs people bring (Biovision, CMU, Mixamo, LAFAN1, MakeHuman, SMPL, Unreal, Rokoko) by name
- standard: the standard poses and the walk cycle, from a mannequin's own joints
"""
