"""One job, from what a user asks to what it made (floor 7: everything below): ``synth``, ``pose``, each row of
``batch``, the Synthesize operator and its live steps ask through a Request and write or show the Result.

- request: what can be asked (measurements, set, options, cushions, skin, pose, outputs), checked whole before work
- make: the mannequin synthesized, its skin, its poses, what was measured and missed
- result: what a job made, as data, and its misses worded
"""
