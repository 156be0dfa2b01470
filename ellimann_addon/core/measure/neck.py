"""The neck girth's axis: a tape laid round the neck square to it, not level (docs/measurements.md).

The neck leans forward (the line from the neck joint to the head joint: 19.4-21.8 degrees from vertical on the
six reference bodies), so a level cut low enough to miss the jaw in front meets the shoulders behind: on the
heavy bodies the smallest level cut ran through the chin. The neck girth is the smallest whole section square to
the neck's axis among the planes that cross the axis between ``NECK_BAND`` He. The axis lies in the sagittal
plane, leaning forward (towards -Y) by a tilt taken from the body:

- a mannequin with joints: the tilt of the line from its Neck joint to its Head joint (the body model's neck01
  and head, carried through synthesis and exact mode);
- a mannequin without joints: ``NECK_TILT_DEFAULT``, the reference bodies' lean (its traced pieces do not lean:
  the neck piece stands vertical, so the tightest tape over them wanders with the gaps between pieces);
- a body mesh (a scan): the tilt whose smallest section is the smallest of all, where a tape drawn tight round
  the neck settles (square to the axis of a cylinder), searched over ``NECK_TILT_RANGE``; or the tilt it is
  given (a mannequin's own mesh, its skin: measured with the mannequin's own tilt).

The axis passes below the middle of the body's front-to-back extent at the band's middle height: that places the
band's ends along the axis; the planes themselves are fixed by the tilt.
"""

import numpy as np

from .band_search import extreme_over_band

NECK_BAND = (0.80, 0.92)  # fractions of He where the cut crosses the neck's axis
NECK_TILT_RANGE = (-10.0, 50.0)  # degrees forward from vertical: the tilts a tape is tried at on a body mesh
NECK_TILT_SAMPLES = 7  # tilts tried over that range (every 10 degrees) before the best is refined
NECK_TILT_STEPS = 8  # golden-section steps on the tilt: its bracket (20 degrees) narrows to 0.4 degree
NECK_TILT_DEFAULT = 20.0  # degrees: a mannequin without joints (the six reference bodies' neck joints: 19.4-21.8)
# SMPL's Neck and Head joints in a mannequin's (24, 3) joints (core.mannequin.skeleton.JOINT_NAMES, a floor above)
NECK_JOINT, HEAD_JOINT = 12, 15


def neck_frame(tilt):
    """Rows of the neck's frame for a forward ``tilt`` (radians): x, then the axis's front-to-back normal, then the
    axis (0, -sin tilt, cos tilt). A rotation (det +1); tilt 0 is the world's own axes."""
    sine, cosine = np.sin(tilt), np.cos(tilt)
    return np.array([[1.0, 0.0, 0.0], [0.0, cosine, sine], [0.0, -sine, cosine]])


def joint_tilt(joints):
    """The forward tilt (radians) of the line from the Neck joint to the Head joint, in the sagittal plane; None
    without joints."""
    if joints is None:
        return None
    axis = np.asarray(joints, float)[HEAD_JOINT] - np.asarray(joints, float)[NECK_JOINT]
    return float(np.arctan2(-axis[1], axis[2]))


def neck_band(height, tilt):
    """(lowest, highest) offset along the axis of the planes square to it that cross it between NECK_BAND He,
    measured from the axis's point at the soles' height."""
    return tuple(fraction * height * np.cos(tilt) for fraction in NECK_BAND)


def tightest_tilt(smallest):
    """(smallest girth, its tilt in radians) over NECK_TILT_RANGE: ``smallest(tilts)`` gives the smallest girth
    square to each tilt of an array (infinity where there is none). NECK_TILT_SAMPLES tilts, then golden section
    beside every local minimum among them (a mannequin's pieces give several, of near-equal depth; the tape's
    girth has kinks where a section gains a piece: no parabola)."""
    low, high = np.radians(NECK_TILT_RANGE)
    return extreme_over_band(smallest, low, high, False, samples=NECK_TILT_SAMPLES, where=True, steps=NECK_TILT_STEPS)
