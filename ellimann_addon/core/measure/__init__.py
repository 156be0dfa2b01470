"""Measuring: the tailor measurements of a mannequin and of a body mesh (floor 2: geometry below it).

- band_search: the extreme of a function over a band (grid, then golden section or parabolic steps)
- body: measuring a body mesh (a scan, another tool's body): the five and the extra measurements
- body_neck: a body mesh's neck, square to its axis (the tilt given, or where a tape drawn tight settles)
- further: measurements beyond the eleven taken on a body mesh (underbust, high hip, depths, bust height, knee,
  ankle, wrist, shoulder to wrist): a body model's inputs
- extra: the six measurements beyond the five (neck, upper arm, thigh, calf, crotch height, arm length)
- neck: the neck girth's axis (its tilt from the joints or the tightest tape) and band
- tailor: m_T, the five tailor measurements of Section 2.3.5 in closed form, batched; the m_T line
"""
