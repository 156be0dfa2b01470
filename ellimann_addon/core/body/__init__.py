"""The body skin: the reference set's own body meshes interpolated for a request and corrected on the mesh until
it measures the request (floor 5: everything below). The bodies themselves are the reference set's
(core.synthesis.bodies).

- model: the body model, a request's measurements -> vertices and joints (IDW over the bodies; replaceable)
- ridge: the ridge body model over a set's body space (any measurements in, their tolerances weighed)
- deform: the smooth deformations the correction moves along (a displacement basis linear in its parameters)
- tape: the measurements the correction aims at, by the body-mesh measurer's own code
- correct: the correction, secant steps on the measurement residuals until the mesh measures the request
- mesh_checks: a body mesh stays closed, 2-manifold, of Euler characteristic 2 and unfolded
- skin: the BodySkin (vertices, faces, bones, posing, measuring) and making one from a set's bodies
"""
