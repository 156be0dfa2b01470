"""Synthesis: tailor measurements -> mannequin, from a reference set (floor 4: mannequin and below).

- bodies: a set's bodies (one topology) stored compactly beside its RMs (``bodies.npz``): mean, offsets, labels,
  bone weights on the 24 joints, each body's joints and measurements; reading, writing and their checks
- body_space: many bodies as a ridge body model's statistics (``body_space.npz``): building one from a bank (its
  bad bodies refused), reading, writing
- batch: a batch in chunks (one core batch each, refused rows alone, extra measurements met) with per-row errors
- extra_refine: exact mode for the six extra measurements, alternated with the five's refinement
- idw: segmented and proportional IDW: the weights, the interpolated pieces and joints
- manifest: a reference-set folder's manifest, ``reference_set.json``
- misses: what exact mode missed, as data (``Miss``), judged and worded in one place
- options: ``SynthesisOptions`` and ``SYNTHESIS``, the table of their values, labels and descriptions
- population: rows of measurements sampled from a survey's statistics (the shipped surveys in populations/)
- reference_set: ``ReferenceSet``: the Reference Mannequins loaded, with what IDW and refinement precompute
- refine: exact mode: the refinement until m_T meets the request
- request: a request checked, its name, the relative error of m_T
- shipped: the shipped reference sets by name (female, male)
- synthesize: ``synthesize`` / ``synthesize_batch`` / ``synthesize_extra``: request, set, IDW and refinement together;
  ``SynthesizedBatch`` (a batch's arrays, per-row errors) and ``Synthesized`` (one mannequin, what it missed)
"""
