"""The body skin: the reference set's own body meshes interpolated for a request and corrected on the mesh until
it measures the request (floor 5: everything below). The bodies themselves are the reference set's
(core.synthesis.bodies).

- model: the body model, a request's measurements -> vertices and joints (IDW over the bodies; replaceable)
- ridge: the ridge body model over a set's body space (any measurements in, their tolerances weighed)
- deform: the smooth deformations the correction moves along (a displacement basis linear in its parameters)
- tape: the measurements the correction aims at, by the body-mesh measurer's own code
- extra_tape: the six extras by the body-mesh measurer's own steps, fast on the fixed topology (the legs from the
  labels), whole or in windows about the last extremes (the correction's loop)
- correct: the correction, secant steps on the measurement residuals until the mesh measures the request
- plausible: what a corrected body may become (proportions, folds, stretch, the arms clear of the trunk) and how far
  a refused measurement reaches
- mesh_checks: a body mesh stays closed, 2-manifold, of Euler characteristic 2 and unfolded
- hips: the bone weights where the hips bend, re-drawn across tilted planes so that sitting keeps the volume
- skin: the BodySkin (vertices, faces, bones, posing, measuring) and making one from a set's bodies
"""
