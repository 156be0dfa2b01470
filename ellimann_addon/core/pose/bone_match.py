"""Which clip bone drives which mannequin joint, and what is left over, said out loud.

A listed rig is known by its names (``core.pose.rig_names``). A rig nobody listed is placed by its names and its
hierarchy: each name gives a side (Left, L, l_, _l, .L, ...) and a part (up/upper + leg or thigh: the thigh;
low/lower + leg, shin, calf, knee: the shin; foot, ankle; toe, ball; clavicle, collar; up/upper + arm; fore,
low/lower + arm, elbow: the forearm; hand, wrist; a finger), and where a word could name two parts its place in
the chain decides: a Leg below a thigh is a shin, otherwise a thigh; a Shoulder above an arm is a collar,
otherwise the upper arm; a sided Hip above a thigh is the pelvis' side (CMU's LHipJoint), otherwise the thigh;
of two feet in one chain the second is the toes. A part the names leave out is filled by the chain: one unnamed
bone between a thigh and a foot is the shin. The spine is the chain from the pelvis to the neck: its first bone
is Spine1, its last Spine3 (where the collars hang), the middle one Spine2.

``match_bones`` takes the listed map that places most joints, or the names-and-hierarchy match when it places
more; ``rig`` forces one. A mannequin joint without a bone follows its parent: between two placed joints of a
limb it will not bend (a knee between a placed hip and ankle), which ``BoneMatch.stiff`` names.
"""

import re
from dataclasses import dataclass

from ..errors import ElliMannError
from ..mannequin.skeleton import CHILDREN, JOINT_COUNT, JOINT_INDEX, JOINT_NAMES, PARENTS, joint_side
from .rig_names import RIG_LABELS, RIG_NAME_MAPS, bare_name, listed_sources

AUTO = "auto"
BY_NAMES = "names"  # the rig key of a match made by names and hierarchy
RIG_CHOICES = (AUTO, *RIG_NAME_MAPS)
# The bone of a joint with several children points at this one (the spine's, not a hip's or a collar's).
PREFERRED_CHILD = {JOINT_INDEX["Pelvis"]: JOINT_INDEX["Spine1"], JOINT_INDEX["Spine3"]: JOINT_INDEX["Neck"]}
LIMB_JOINTS = ("Hip", "Knee", "Ankle", "Collar", "Shoulder", "Elbow", "Wrist")  # one of them makes a clip usable
LEG = ("Hip", "Knee", "Ankle", "Foot")
ARM = ("Collar", "Shoulder", "Elbow", "Wrist")

_PIECES = re.compile(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+")
_SIDES = {"left": "L", "l": "L", "lft": "L", "lt": "L", "right": "R", "r": "R", "rgt": "R", "rt": "R"}
_SKIP = set(
    "twist roll end tip nub ik fk pole target ctrl control helper mch eye eyes jaw tongue teeth top site dummy "
    "null prop weapon bend metacarpal carpal breast ear nose brow lip cheek hair tail wing".split()
)
_FINGERS = {"thumb", "index", "middle", "ring", "pinky", "pinkie", "little", "finger", "fingers", "digit"}
_SPINE = {"spine", "chest", "back", "torso", "abdomen", "belly", "waist", "ribs", "thorax", "lumbar"}


def name_words(name):
    """(side 'L', 'R' or None, lower-case words without side and digits) of a bone name."""
    words = []
    for chunk in re.split(r"[^A-Za-z0-9]+", bare_name(name)):
        for piece in _PIECES.findall(chunk):
            piece = piece.lower()
            glued = re.fullmatch(r"(left|right)([a-z]{3,})", piece)  # LEFTUPLEG, lefthand
            words += list(glued.groups()) if glued else [piece]
    sides = {_SIDES[w] for w in words if w in _SIDES}
    side = sides.pop() if len(sides) == 1 else None
    return side, [w for w in words if w not in _SIDES and not w.isdigit()]


def bone_part(name):
    """(side, part) a bone's name says: part one of LEG, ARM, 'finger' (sided); 'Pelvis', 'root', 'spine', 'Neck',
    'Head' (central); 'leg', 'arm', 'shoulder', 'hip' where the chain must decide; 'skip' for helpers (twist, roll,
    end, IK, ...); None when it says nothing."""
    side, words = name_words(name)
    have, joined = set(words), "".join(words)
    if have & _SKIP or "twist" in joined or "roll" in joined:
        return side, "skip"
    if have & _FINGERS or "finger" in joined:
        return side, "finger" if side else None
    up, low = bool(have & {"up", "upper", "hi", "high"}), bool(have & {"low", "lower", "lo", "fore"})
    if side is None:
        central = (
            ("Pelvis", have & {"hips", "pelvis", "hip"}),
            ("root", have & {"root"}),
            ("Neck", have & {"neck"} or "neck" in joined),
            ("Head", have & {"head"}),
            ("spine", have & _SPINE or "spine" in joined),
        )
        return None, next((part for part, found in central if found), None)
    sided = (
        ("Foot", have & {"toe", "toes", "ball"} or "toe" in joined),
        ("Ankle", have & {"foot", "ankle"} or "foot" in joined),
        ("Hip", have & {"thigh", "femur"} or any(w in joined for w in ("upleg", "upperleg", "thigh"))),
        ("Knee", have & {"shin", "calf", "knee", "tibia"} or any(w in joined for w in ("lowleg", "lowerleg", "loleg"))),
        ("Knee" if low else "Hip" if up else "leg", "leg" in have or joined.endswith("leg")),
        ("Collar", have & {"clavicle", "collar", "collarbone", "scapula", "clav"} or "clavicle" in joined),
        ("Elbow", have & {"elbow", "radius", "ulna"} or any(w in joined for w in ("forearm", "lowarm", "lowerarm"))),
        ("Shoulder", have & {"humerus"} or any(w in joined for w in ("uparm", "upperarm"))),
        ("Elbow" if low else "Shoulder" if up else "arm", "arm" in have or joined.endswith("arm")),
        ("shoulder", "shoulder" in joined),
        ("Wrist", have & {"hand", "wrist", "palm"} or "hand" in joined),
        ("hip", "hip" in have),
    )
    return side, next((part for part, found in sided if found), None)


class _Tree:
    def __init__(self, parents):
        self.parents = list(parents)
        self.children = [[] for _ in parents]
        for bone, parent in enumerate(parents):
            if parent >= 0:
                self.children[parent].append(bone)
        self.depth = [self._depth(b) for b in range(len(parents))]

    def _depth(self, bone):
        depth = 0
        while self.parents[bone] >= 0:
            bone, depth = self.parents[bone], depth + 1
        return depth

    def ancestors(self, bone):
        out = []
        while self.parents[bone] >= 0:
            bone = self.parents[bone]
            out.append(bone)
        return out

    def descendants(self, bone):
        out, todo = [], list(self.children[bone])
        while todo:
            out.append(todo.pop())
            todo += self.children[out[-1]]
        return out

    def between(self, top, bottom):
        """The bones strictly between ``top`` and its descendant ``bottom``, top down."""
        path = []
        for bone in self.ancestors(bottom):
            if bone == top:
                return path[::-1]
            path.append(bone)
        return None


def match_by_names(names, parents):
    """{SMPL joint name: clip bone index} placed by the bones' names and the hierarchy (see the module's notes)."""
    tree = _Tree(parents)
    parts = [list(bone_part(n)) for n in names]
    order = sorted(range(len(names)), key=lambda b: tree.depth[b])

    def kin(bone, relatives, wanted):
        return any(parts[r][0] == parts[bone][0] and parts[r][1] in wanted for r in relatives)

    for bone in order:  # the words that name two parts: the chain decides
        part = parts[bone][1]
        below = tree.descendants(bone)
        if part == "hip":
            thigh_below = kin(bone, below, ("Hip",)) or any(
                parts[r][1] == "leg" and kin(r, tree.descendants(r), ("Knee", "leg")) for r in below
            )
            parts[bone][1] = "skip" if thigh_below else "Hip"
        elif part == "shoulder":
            parts[bone][1] = "Collar" if kin(bone, below, ("Shoulder", "arm")) else "Shoulder"
    for bone in order:
        part, above = parts[bone][1], tree.ancestors(bone)
        if part == "leg":
            parts[bone][1] = "Knee" if kin(bone, above, ("Hip",)) else "Hip"
        elif part == "arm":
            parts[bone][1] = "Elbow" if kin(bone, above, ("Shoulder",)) else "Shoulder"
    for bone in order:  # a second foot below a foot is the toes; a second hand below a hand, the fingers
        side, part = parts[bone]
        shifted = {"Ankle": "Foot", "Wrist": "finger"}.get(part)
        if shifted and kin(bone, tree.ancestors(bone), (part,)) and not kin(bone, tree.descendants(bone), (shifted,)):
            parts[bone][1] = shifted
    found = {}
    for bone in order:
        side, part = parts[bone]
        key = f"{side}_{part}" if side and part in LEG + ARM else part
        found.setdefault(key, bone)
    out = {}
    pelvis = found.get("Pelvis", found.get("root"))
    for side in "LR":
        for chain in (LEG, ARM):
            _fill_chain(chain, side, found, parts, tree)
            out.update({f"{side}_{p}": found[f"{side}_{p}"] for p in chain if f"{side}_{p}" in found})
        wrist = found.get(f"{side}_Wrist")
        if wrist is not None:
            fingers = [b for b in tree.descendants(wrist) if parts[b] == [side, "finger"]]
            if fingers:
                out[f"{side}_Hand"] = min(fingers, key=lambda b: (tree.depth[b], _finger_rank(names[b]), b))
    if pelvis is None:  # the thighs' parent, else the hierarchy's root
        tops = [out[f"{s}_Hip"] for s in "LR" if f"{s}_Hip" in out and parents[out[f"{s}_Hip"]] >= 0]
        pelvis = parents[tops[0]] if tops else tree.parents.index(-1)
    out["Pelvis"] = pelvis
    below_pelvis = set(tree.descendants(pelvis))
    for part in ("Neck", "Head"):
        first = next((b for b in order if parts[b][1] == part and b in below_pelvis), None)
        if first is not None:
            out[part] = first
    spine = _spine(out, pelvis, tree)
    spine = [b for b in spine if parts[b][1] not in ("skip", "Pelvis") and parts[b][0] is None]
    picks = {1: (0,), 2: (0, 1)}.get(len(spine), (0, len(spine) // 2, len(spine) - 1))
    out.update({f"Spine{k + 1}": spine[i] for k, i in enumerate(picks) if spine})
    return out


def _spine(out, pelvis, tree):
    """The bones from the pelvis (excluded) up to the neck (excluded), else the head, else the bone the collars
    or the upper arms hang on (included)."""
    top = out.get("Neck", out.get("Head"))
    if top is not None:
        return tree.between(pelvis, top) or []
    arms = [out[f"{s}_{p}"] for s in "LR" for p in ("Collar", "Shoulder") if f"{s}_{p}" in out]
    shared = [b for b in tree.ancestors(arms[0]) if all(b in tree.ancestors(a) for a in arms)] if arms else []
    if not shared or shared[0] == pelvis or tree.between(pelvis, shared[0]) is None:
        return []
    return tree.between(pelvis, shared[0]) + shared[:1]


def _finger_rank(name):
    _, words = name_words(name)
    return 0 if {"middle", "base"} & set(words) or re.search(r"3(\D|$)", name) else 1


def _fill_chain(chain, side, found, parts, tree):
    """Fill the parts of one limb its names left out by the bones' places in the chain: unnamed bones of the same
    side between two named parts, above the first or below the last (one child at a time)."""

    def free(bone):
        return parts[bone][0] in (side, None) and parts[bone][1] is None

    keys = [f"{side}_{p}" for p in chain]
    named = [i for i, k in enumerate(keys) if k in found]
    if not named:
        return
    for a, b in zip(named, named[1:]):
        path = tree.between(found[keys[a]], found[keys[b]]) or []
        path = [bone for bone in path if free(bone)]
        for key, bone in zip(keys[a + 1 : b], path):
            found[key] = bone
    bone = found[keys[named[0]]]
    for key in reversed(keys[: named[0]]):
        bone = tree.parents[bone]
        if bone < 0 or not free(bone) or parts[bone][0] != side:
            break
        found[key] = bone
    bone = found[keys[named[-1]]]
    for key in keys[named[-1] + 1 :]:
        kids = [k for k in tree.children[bone] if free(k) and parts[k][0] == side]
        if len(kids) != 1:
            break
        bone = found[key] = kids[0]


@dataclass
class BoneMatch:
    """Which clip bone drives which mannequin joint."""

    rig: str  # a key of RIG_NAME_MAPS, or BY_NAMES
    names: list  # the clip's bones
    sources: dict  # {joint index: clip bone index}

    @property
    def label(self):
        return "its names and hierarchy (no listed rig)" if self.rig == BY_NAMES else f"{RIG_LABELS[self.rig]} names"

    @property
    def unplaced(self):
        """The clip's bones that drive no joint."""
        used = set(self.sources.values())
        return [n for i, n in enumerate(self.names) if i not in used]

    @property
    def unsourced(self):
        """The mannequin's joints no bone drives (they follow their parents)."""
        return [JOINT_NAMES[j] for j in range(JOINT_COUNT) if j not in self.sources]

    def segment_end(self, joint):
        """The nearest driven joint below ``joint`` along its bone (the preferred child where it has several), or
        None."""
        child = joint
        while True:
            kids = CHILDREN[child]
            child = PREFERRED_CHILD.get(child, kids[0] if len(kids) == 1 else None)
            if child is None:
                return None
            if child in self.sources:
                return child

    @property
    def stiff(self):
        """{joint name: (driven joint above, driven joint below)} of the limbs' joints without a bone between two
        driven ones: they will not bend."""
        out = {}
        for j in range(JOINT_COUNT):
            if j in self.sources or joint_side(JOINT_NAMES[j]) == "C":
                continue
            above = PARENTS[j]
            while above >= 0 and above not in self.sources:
                above = PARENTS[above]
            below = self.segment_end(j)
            if above >= 0 and below is not None:
                out[JOINT_NAMES[j]] = (JOINT_NAMES[above], JOINT_NAMES[below])
        return out

    def lines(self):
        """What the match placed and what it did not, a line each (the last one only when joints will not bend)."""
        out = [f"{len(self.sources)} of {JOINT_COUNT} joints placed from {len(self.names)} bones by {self.label}"]
        if self.unplaced:
            out.append(f"bones not placed ({len(self.unplaced)}): {', '.join(self.unplaced)}")
        if self.unsourced:
            out.append(
                f"joints without a bone ({len(self.unsourced)}, they follow their parents): {', '.join(self.unsourced)}"
            )
        return out

    def stiff_line(self):
        """The warning of the limbs' joints that will not bend, or None."""
        stiff = self.stiff
        if not stiff:
            return None
        listed = ", ".join(f"{j} (between {a} and {b})" for j, (a, b) in stiff.items())
        return f"will not bend, the clip has no bone for them: {listed}"


def match_bones(names, parents, rig=AUTO, source="the clip"):
    """The BoneMatch of a clip's bones (``names``, ``parents``): ``rig`` a key of RIG_NAME_MAPS, or AUTO: the listed
    map that places most joints (the first on a tie), or names and hierarchy when they place more. ElliMannError
    naming ``source`` when no limb is placed."""
    if rig != AUTO and rig not in RIG_NAME_MAPS:
        raise ElliMannError(f"rig: unknown rig {rig!r}; expected one of {', '.join(RIG_CHOICES)}")
    keys = list(RIG_NAME_MAPS) if rig == AUTO else [rig]
    candidates = [(key, listed_sources(key, names)) for key in keys]
    if rig == AUTO:
        candidates.append((BY_NAMES, match_by_names(names, parents)))
    key, found = max(candidates, key=lambda c: len(c[1]))  # max keeps the first of equals
    limbs = [j for j in found if j[2:] in LIMB_JOINTS]
    if not limbs:
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        if rig != AUTO:
            raise ElliMannError(
                f"bones: no limb of the {len(names)} bones of {source} ({shown}) is in the {RIG_LABELS[rig]} map; "
                f"try --rig auto"
            )
        raise ElliMannError(
            f"bones: no limb recognised among the {len(names)} bones of {source} ({shown}): no listed rig's names "
            f"({', '.join(RIG_NAME_MAPS)}) and no side and part in a name (LeftUpLeg, thigh_l, upperarm.L, ...)"
        )
    return BoneMatch(key, list(names), {JOINT_INDEX[j]: b for j, b in found.items()})
