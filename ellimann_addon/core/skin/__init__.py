"""A smooth skin over a mannequin's pieces: one closed surface that follows the pieces and the bones, and meets
the measurements (floor 5: everything below).

- contour: the zero level set of a sampled field as a closed 2-manifold mesh (a watertight marching-cubes table)
- field: the pieces' signed distance, neighbours in the body blended, sampled finely only near the surface
- settings: a skin's voxel and blend, their table, and the checks made before any work
- surface: the Skin (mesh, weights, how it was made), building it, following the pieces, measuring it
- exact: exact mode on the skin: the pieces refined until their skin measures the request
- measure: the skin measured by m_T's definitions, on the surface itself and on its mesh
- weights: the pieces each vertex follows, and following them
- skinning: bone weights for linear-blend skinning: smooth across the joints, keeping the volume as the legs bend
"""
