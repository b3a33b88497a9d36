"""Which source joint plays which HumanML3D template joint: named dialects and `auto` (A §3.1).

A joint map sends each of the 22 template joint names to a source joint name, or to a point between
two source joints, `("between", a, b, t)` = a + t·(b − a), for skeletons with fewer spine joints.
`auto` reads joint names (Left/Right/L/R/_L/_R markers; UpLeg/Thigh/…) and falls back on the tree's
structure where names are ambiguous: the knee is the ankle's parent, the upper arm the forearm's
parent (so 'Shoulder' resolves to a collar bone in one convention and an upper arm in another), the
pelvis is where the legs meet, the upper spine where the arms branch.
"""
from __future__ import annotations

import re

import numpy as np

from ..motion.skeleton import JOINT_NAMES, REFERENCE_BONE_LENGTHS, Skeleton

_SIDES = ("left", "right")
# where spine1 and spine2 sit along the template's pelvis → spine3 path (fractions of its length)
_SPINE = REFERENCE_BONE_LENGTHS[[2, 5, 8]]  # bones of joints 3, 6, 9
SPINE_FRACTIONS = (_SPINE[0] / _SPINE.sum(), _SPINE[:2].sum() / _SPINE.sum())

# the CMU skeleton of the Xia set (as retargeted by Aberman et al.); also plain CMU BVH. LowerBack,
# Neck and the Shoulders have zero offsets there (they sit on Hips and Spine1), so points between
# joints stand in for spine2 and the collars, and Neck1 for the neck.
XIA = {
    "pelvis": "Hips", "left_hip": "LeftUpLeg", "right_hip": "RightUpLeg", "spine1": "Spine",
    "left_knee": "LeftLeg", "right_knee": "RightLeg", "spine2": ("between", "Spine", "Spine1", 0.5),
    "left_ankle": "LeftFoot", "right_ankle": "RightFoot", "spine3": "Spine1", "left_foot": "LeftToeBase",
    "right_foot": "RightToeBase", "neck": "Neck1", "left_collar": ("between", "Spine1", "LeftArm", 0.5),
    "right_collar": ("between", "Spine1", "RightArm", 0.5), "head": "Head", "left_shoulder": "LeftArm",
    "right_shoulder": "RightArm", "left_elbow": "LeftForeArm", "right_elbow": "RightForeArm",
    "left_wrist": "LeftHand", "right_wrist": "RightHand",
}
STYLE100 = {  # 100STYLE (Mason et al. 2022): 'Shoulder' is the upper arm, 'Hip' the thigh
    "pelvis": "Hips", "left_hip": "LeftHip", "right_hip": "RightHip", "spine1": "Chest",
    "left_knee": "LeftKnee", "right_knee": "RightKnee", "spine2": "Chest2", "left_ankle": "LeftAnkle",
    "right_ankle": "RightAnkle", "spine3": "Chest4", "left_foot": "LeftToe", "right_foot": "RightToe",
    "neck": "Neck", "left_collar": "LeftCollar", "right_collar": "RightCollar", "head": "Head",
    "left_shoulder": "LeftShoulder", "right_shoulder": "RightShoulder", "left_elbow": "LeftElbow",
    "right_elbow": "RightElbow", "left_wrist": "LeftWrist", "right_wrist": "RightWrist",
}


def builtin_map() -> dict:
    """The map of the built-in style corpus's mocap skeleton (mslib.data.mocap_skeleton)."""
    from .mocap_skeleton import MOCAP_TO_TEMPLATE
    return {JOINT_NAMES[t]: name for name, t in sorted(MOCAP_TO_TEMPLATE.items(), key=lambda kv: kv[1])}


DIALECTS = {"xia": lambda: dict(XIA), "cmu": lambda: dict(XIA), "100style": lambda: dict(STYLE100),
            "builtin": builtin_map}


# ---------------------------------------------------------------- reading names
def _core(name: str) -> str:
    """The joint name without a namespace ('mixamorig:LeftArm' → 'LeftArm')."""
    return re.split(r"[:|]", name)[-1]


def joint_side(name: str):
    """'left', 'right' or None from markers like Left…, L…, l_…, …_L, ….l, Bip01_L_…."""
    n = _core(name)
    low = n.lower()
    for side, word, letter in (("left", "left", "l"), ("right", "right", "r")):
        if word in low:
            return side
        if re.match(rf"^{letter.upper()}(?=[A-Z_.\s])", n) or re.match(rf"^{letter}[_.\s]", n, re.I):
            return side
        if re.search(rf"[_.\s]{letter}([_.\s]|$)", n, re.I):
            return side
    return None


_PART_PATTERNS = (  # first match wins: the more specific patterns come first
    ("finger", r"thumb|index|middle|ring|pinky|finger|fing"),
    ("toe", r"toe"),
    ("forearm", r"forearm|lowerarm|lowarm|elbow"),
    ("upperarm", r"upperarm|uparm|arm"),
    ("hand", r"hand|wrist"),
    ("collar", r"collar|clavicle"),
    ("shoulder", r"shoulder"),
    ("upleg", r"upleg|upperleg|thigh"),
    ("hip", r"hip"),
    ("knee", r"lowerleg|lowleg|knee|shin|calf|leg"),
    ("ankle", r"foot|ankle"),
    ("neck", r"neck"),
    ("head", r"head"),
    ("spine", r"spine|chest|back|torso|abdomen"),
)


def joint_part(name: str):
    """The body part a joint name suggests ('upleg', 'knee', 'shoulder', …) or None."""
    low = _core(name).lower()
    low = re.sub(r"^(left|right)|(left|right)$", "", low)
    low = re.sub(r"^[lr][_.\s]|[_.\s][lr]$", "", low)
    if re.match(r"^[lr](?=[a-z])", low) and re.match(r"^[LR][A-Z]", _core(name)):
        low = low[1:]
    for part, pattern in _PART_PATTERNS:
        if re.search(pattern, low):
            return part
    return None


# ---------------------------------------------------------------- the tree
def _ancestors(skeleton: Skeleton, j: int) -> list:
    out = []
    while j >= 0:
        out.append(j)
        j = skeleton.parents[j]
    return out  # j, parent, …, root


def _lca(skeleton: Skeleton, a: int, b: int) -> int:
    up = set(_ancestors(skeleton, a))
    return next(j for j in _ancestors(skeleton, b) if j in up)


def _path_between(skeleton: Skeleton, top: int, bottom: int) -> list:
    """Joints strictly between an ancestor `top` and its descendant `bottom`, top-down."""
    chain = _ancestors(skeleton, bottom)
    if top not in chain:
        return []
    return chain[1:chain.index(top)][::-1]


def auto_joint_map(skeleton: Skeleton, source: str = "skeleton") -> dict:
    """Guess the template map of any humanoid skeleton from names and structure (see module doc)."""
    names = skeleton.names
    scale = max(float(skeleton.bone_lengths().max()), 1e-12)
    # a joint with a zero offset sits on its parent: a poor stand-in for a template joint
    zero = [float(v) < 1e-6 * scale for v in skeleton.bone_lengths()]
    zero[0] = False
    side = [joint_side(n) for n in names]
    part = [joint_part(n) for n in names]
    found, missing = {}, []

    def pick(s, parts, below=None):
        """The shallowest joint of side s whose part is in `parts` (below an ancestor if given)."""
        cands = [j for j in range(len(names)) if side[j] == s and part[j] in parts]
        if below is not None:
            cands = [j for j in cands if below in _ancestors(skeleton, j) and j != below]
        return min(cands, key=lambda j: len(_ancestors(skeleton, j))) if cands else None

    def parent_of(j):
        return None if j is None or skeleton.parents[j] < 0 else skeleton.parents[j]

    for s in _SIDES:
        hand = pick(s, {"hand"})
        fore = next((j for j in _ancestors(skeleton, hand)[1:] if part[j] == "forearm"), None) \
            if hand is not None else None
        fore = fore if fore is not None else parent_of(hand)
        upper = next((j for j in _ancestors(skeleton, fore)[1:] if part[j] == "upperarm"), None) \
            if fore is not None else None
        upper = upper if upper is not None else parent_of(fore)
        collar = parent_of(upper)
        if collar is not None and (side[collar] != s or zero[collar]):
            collar = None  # arms hang straight from the spine: a point between is placed below
        ankle = pick(s, {"ankle"})
        toe = pick(s, {"toe"}, below=ankle) if ankle is not None else None
        if toe is None and ankle is not None and skeleton.children(ankle):
            toe = skeleton.children(ankle)[0]
        knee = next((j for j in _ancestors(skeleton, ankle)[1:] if part[j] == "knee"), None) \
            if ankle is not None else None
        knee = knee if knee is not None else parent_of(ankle)
        hip = next((j for j in _ancestors(skeleton, knee)[1:] if part[j] == "upleg"), None) \
            if knee is not None else None
        hip = hip if hip is not None else parent_of(knee)
        for tname, j in (("wrist", hand), ("elbow", fore), ("shoulder", upper), ("collar", collar),
                         ("ankle", ankle), ("foot", toe), ("knee", knee), ("hip", hip)):
            if j is not None:
                found[f"{s}_{tname}"] = names[j]
            elif tname != "collar":
                missing.append(f"{s}_{tname}")

    idx = {n: i for i, n in enumerate(names)}
    if "left_hip" in found and "right_hip" in found:
        pelvis = _lca(skeleton, idx[found["left_hip"]], idx[found["right_hip"]])
        found["pelvis"] = names[pelvis]
    else:
        missing.append("pelvis")
    arm_tops = [found.get(f"{s}_collar", found.get(f"{s}_shoulder")) for s in _SIDES]
    heads = [j for j in range(len(names)) if part[j] == "head" and side[j] is None]
    if heads:
        head = min(heads, key=lambda j: len(_ancestors(skeleton, j)))
        found["head"] = names[head]
        necks = [j for j in _ancestors(skeleton, head)[1:][::-1] if part[j] == "neck" and not zero[j]]
        found["neck"] = names[necks[0] if necks else skeleton.parents[head]]
    else:
        missing += ["head", "neck"]
    if None not in arm_tops and "pelvis" in found:
        spine3 = _lca(skeleton, idx[arm_tops[0]], idx[arm_tops[1]])
        found["spine3"] = names[spine3]
        between = [j for j in _path_between(skeleton, idx[found["pelvis"]], spine3) if not zero[j]]
        # choose the joints whose height along the spine best matches the template's spine1/spine2
        lengths = skeleton.bone_lengths()
        along = np.cumsum([lengths[j] for j in between + [spine3]])
        frac = along[:-1] / max(along[-1], 1e-12)
        if len(between) >= 2:
            k1 = int(np.argmin(np.abs(frac[:-1] - SPINE_FRACTIONS[0])))
            k2 = k1 + 1 + int(np.argmin(np.abs(frac[k1 + 1:] - SPINE_FRACTIONS[1])))
            found["spine1"], found["spine2"] = names[between[k1]], names[between[k2]]
        elif len(between) == 1:
            found["spine1"] = names[between[0]]
            found["spine2"] = ("between", names[between[0]], names[spine3], 0.5)
        else:
            found["spine1"] = ("between", found["pelvis"], names[spine3], 1 / 3)
            found["spine2"] = ("between", found["pelvis"], names[spine3], 2 / 3)
        for s in _SIDES:
            if f"{s}_collar" not in found and f"{s}_shoulder" in found:
                found[f"{s}_collar"] = ("between", names[spine3], found[f"{s}_shoulder"], 0.5)
    else:
        missing += ["spine1", "spine2", "spine3"]
    if missing:
        raise ValueError(f"{source}: could not map template joints {sorted(set(missing))} from joints "
                         f"{list(names)}; pass a named dialect ({', '.join(DIALECTS)}) or a joint map")
    return {t: found[t] for t in JOINT_NAMES}


def resolve_joint_map(skeleton: Skeleton, dialect="auto", source: str = "skeleton") -> dict:
    """A complete, checked joint map for `skeleton` from a dialect name, 'auto' or a dict."""
    if isinstance(dialect, dict):
        jmap = dict(dialect)
    elif dialect == "auto":
        return auto_joint_map(skeleton, source)
    elif dialect in DIALECTS:
        jmap = DIALECTS[dialect]()
    else:
        raise ValueError(f"dialect: unknown {dialect!r}; choose one of {['auto', *DIALECTS]}")
    unmapped = [t for t in JOINT_NAMES if t not in jmap]
    absent = sorted({n for v in jmap.values() for n in ([v] if isinstance(v, str) else v[1:3])
                     if n not in skeleton.names})
    if unmapped or absent:
        raise ValueError(f"{source}: dialect {dialect if isinstance(dialect, str) else 'map'!r} does not "
                         f"fit: template joints not mapped {unmapped}, source joints not in the file {absent}")
    return {t: jmap[t] for t in JOINT_NAMES}
