"""File formats ElliMann writes without Blender, and the table of every format (floor 6: everything below).

- avatar: an avatar for garment tools: the skin on the 24 bones (SMPL or Mixamo names), T- or A-pose, the pieces
  as a collision proxy, a decimated skin (over the pieces, or the body skin) measured again; a job's AvatarOptions
- bvh: BVH motion-capture clips read with numpy, their units said, their bones matched
- core_writers: OBJ, JSON and MJCF mannequin files by extension, with a skin or not
- glb: a .glb's JSON chunk and ElliMann's extras in it, read with the standard library (measure of a .glb)
- mjcf: MJCF (MuJoCo) of a mannequin's convex pieces
- mjcf_articulated: MJCF of a mannequin with joints: an articulated body, poses as keyframes
- mjcf_skin: a skin in MJCF (MuJoCo's deformable skin, drawn only), bound to the world or to the 24 bones
- obj: Wavefront OBJ of a mannequin's pieces or of its skin alone, rest or posed, Y up
- npz_bundle: a whole batch in one compressed .npz (streamed row by row, or in one go), and its loader
- posed_files: posed .json, .xml and .obj; reading a pose file
- table: the one table of output formats (extension, writer, whole-file check, needs Blender, needs a skin: fbx)
"""
