"""The style corpus's "mocap" skeleton: 32 joints, other names, a T-pose rest, centimetres, 30 fps.

Paper A's benchmark mixes datasets recorded on different skeletons; the built-in style corpus
imitates that. Its takes are written as BVH files on this skeleton, and a retargeting step (mslib/data/retarget.py,
notebook 01) brings them back to the HumanML3D template.

Design — every template joint coincides with a mocap joint, so retargeting can recover the template
motion exactly:
- 22 joints map one-to-one onto the template (`MOCAP_TO_TEMPLATE`); 10 extra joints are fixed
  offsets in a bone's frame with identity rotation: LHipJoint/RHipJoint and LowerBack halfway along
  the pelvis→hip and pelvis→spine bones, Neck1 halfway along the neck, toe ends, index fingers and
  thumbs.
- Rest pose: a T-pose (arms straight out along ±X, spine and neck straight up, feet flat along +Z).
  A constant per-joint rotation C_j takes the mocap rest direction of a bone to the template body's,
  and local rotations convert as R'_j = C_parentᵀ · R_j · C_j, so both skeletons put every shared
  joint at the same place.
- Units: centimetres; Y up, facing +Z like the template; rotation channels Z, X, Y.
"""
from __future__ import annotations

import numpy as np

from ..motion.skeleton import JOINT_NAMES, Skeleton
from . import kin

CM = 100.0
FPS = 30.0
ROTATION_ORDER = "ZXY"

# (name, parent, template joint or None, note) — parents listed before children
_JOINTS = (
    ("Hips", None, 0), ("LHipJoint", "Hips", None), ("LeftUpLeg", "LHipJoint", 1),
    ("LeftLeg", "LeftUpLeg", 4), ("LeftFoot", "LeftLeg", 7), ("LeftToeBase", "LeftFoot", 10),
    ("LeftToeEnd", "LeftToeBase", None),
    ("RHipJoint", "Hips", None), ("RightUpLeg", "RHipJoint", 2), ("RightLeg", "RightUpLeg", 5),
    ("RightFoot", "RightLeg", 8), ("RightToeBase", "RightFoot", 11), ("RightToeEnd", "RightToeBase", None),
    ("LowerBack", "Hips", None), ("Spine", "LowerBack", 3), ("Spine1", "Spine", 6),
    ("Spine2", "Spine1", 9), ("Neck", "Spine2", 12), ("Neck1", "Neck", None), ("Head", "Neck1", 15),
    ("LeftShoulder", "Spine2", 13), ("LeftArm", "LeftShoulder", 16), ("LeftForeArm", "LeftArm", 18),
    ("LeftHand", "LeftForeArm", 20), ("LeftHandIndex1", "LeftHand", None),
    ("LeftHandThumb1", "LeftHand", None),
    ("RightShoulder", "Spine2", 14), ("RightArm", "RightShoulder", 17),
    ("RightForeArm", "RightArm", 19), ("RightHand", "RightForeArm", 21),
    ("RightHandIndex1", "RightHand", None), ("RightHandThumb1", "RightHand", None),
)
NAMES = tuple(j[0] for j in _JOINTS)
PARENTS = tuple(-1 if j[1] is None else NAMES.index(j[1]) for j in _JOINTS)
MOCAP_TO_TEMPLATE = {j[0]: j[2] for j in _JOINTS if j[2] is not None}
TEMPLATE_JOINTS = tuple(NAMES.index(name) for name, _ in sorted(MOCAP_TO_TEMPLATE.items(), key=lambda kv: kv[1]))
"""Mocap joint index of template joint 0..21: positions[:, TEMPLATE_JOINTS] are the template's."""

_HALFWAY = {"LHipJoint": 1, "RHipJoint": 2, "LowerBack": 3, "Neck1": 15}  # split bone (template)
_T_POSE = {  # mocap rest direction of the bone leaving a template joint (toward its one child)
    1: (0, -1, 0), 2: (0, -1, 0), 4: (0, -1, 0), 5: (0, -1, 0), 7: (0, 0, 1), 8: (0, 0, 1),
    3: (0, 1, 0), 6: (0, 1, 0), 12: (0, 1, 0), 13: (1, 0, 0), 14: (-1, 0, 0), 16: (1, 0, 0),
    17: (-1, 0, 0), 18: (1, 0, 0), 19: (-1, 0, 0),
}
_TEMPLATE_CHILD = {1: 4, 2: 5, 4: 7, 5: 8, 7: 10, 8: 11, 3: 6, 6: 9, 12: 15, 13: 16, 14: 17,
                   16: 18, 17: 19, 18: 20, 19: 21}
_SAME_FRAME = {10: 7, 11: 8, 15: 12, 20: 18, 21: 19}  # leaves carry on their parent's rest frame
_EXTRA = {  # extra leaf joints: offset in the parent's mocap frame, as a fraction of a bone length
    "LeftToeEnd": ((0, 0, 1), 10, 0.45), "RightToeEnd": ((0, 0, 1), 11, 0.45),
    "LeftHandIndex1": ((1, 0, 0), 20, 0.33), "RightHandIndex1": ((-1, 0, 0), 21, 0.33),
    "LeftHandThumb1": ((0.5, -0.2, 0.8), 20, 0.15), "RightHandThumb1": ((-0.5, -0.2, 0.8), 21, 0.15),
}
END_SITES = {"Head": (0, 12.0, 0), "LeftToeEnd": (0, 0, 2.0), "RightToeEnd": (0, 0, 2.0),
             "LeftHandIndex1": (3.0, 0, 0), "RightHandIndex1": (-3.0, 0, 0),
             "LeftHandThumb1": (1.5, 0, 1.5), "RightHandThumb1": (-1.5, 0, 1.5)}


def _between(a, b) -> np.ndarray:
    """The shortest-arc rotation (3, 3) taking direction a onto direction b."""
    a = np.asarray(a, float) / np.linalg.norm(a)
    b = np.asarray(b, float) / np.linalg.norm(b)
    return kin.between(a[:, None], b[:, None])[..., 0]


def rest_corrections(template: Skeleton) -> np.ndarray:
    """C_j (22, 3, 3): the mocap rest frame of each template joint, in the template body's frame."""
    C = np.broadcast_to(np.eye(3), (22, 3, 3)).copy()
    for j, d in _T_POSE.items():
        C[j] = _between(d, template.offsets[_TEMPLATE_CHILD[j]])
    for j, p in _SAME_FRAME.items():
        C[j] = C[p]
    return C


def mocap_skeleton(template: Skeleton, corrections=None) -> Skeleton:
    """The mocap skeleton (centimetres) of a template body (e.g. a generated clip's skeleton)."""
    if template.n_joints != 22:
        raise ValueError(f"template: expected the 22-joint HumanML3D tree, got {template.n_joints} joints")
    C = rest_corrections(template) if corrections is None else corrections
    tp = template.parents
    offsets = np.zeros((len(NAMES), 3))
    lengths = template.bone_lengths()
    for m, (name, parent, j) in enumerate(_JOINTS):
        if name in _HALFWAY:
            t = _HALFWAY[name]
            offsets[m] = 0.5 * C[tp[t]].T @ template.offsets[t]
        elif name in _EXTRA:
            direction, bone, frac = _EXTRA[name]
            offsets[m] = np.asarray(direction, float) / np.linalg.norm(direction) * frac * lengths[bone]
        elif j is not None and j > 0:
            o = C[tp[j]].T @ template.offsets[j]
            offsets[m] = 0.5 * o if NAMES[PARENTS[m]] in _HALFWAY else o
    return Skeleton(NAMES, PARENTS, offsets * CM)


def mocap_rotations(template_rotations, template: Skeleton, corrections=None) -> np.ndarray:
    """Template local rotations (T, 22, 3, 3) → mocap local rotations (T, 32, 3, 3)."""
    R = np.asarray(template_rotations, float)
    if R.ndim != 4 or R.shape[1:] != (22, 3, 3):
        raise ValueError(f"template_rotations: expected (T, 22, 3, 3), got {R.shape}")
    C = rest_corrections(template) if corrections is None else corrections
    tp = template.parents
    out = np.broadcast_to(np.eye(3), (R.shape[0], len(NAMES), 3, 3)).copy()
    for m, (_, _, j) in enumerate(_JOINTS):
        if j is None:
            continue
        Cp = np.eye(3) if tp[j] < 0 else C[tp[j]]
        out[:, m] = Cp.T @ R[:, j] @ C[j]
    return out


def to_bvh_motion(rotations, root, template: Skeleton, fps: float = FPS):
    """A template motion (local rotations (T, 22, 3, 3), root (T, 3) in metres) as a BVHMotion on
    the mocap skeleton, in centimetres."""
    from ..motion.bvh import BVHMotion
    C = rest_corrections(template)
    sk = mocap_skeleton(template, C)
    sites = {NAMES.index(k): np.asarray(v, float) for k, v in END_SITES.items()}
    return BVHMotion.from_arrays(sk, mocap_rotations(rotations, template, C), np.asarray(root) * CM, fps,
                                 rotation_order=ROTATION_ORDER, end_sites=sites)


def template_positions(mocap_positions) -> np.ndarray:
    """Mocap global positions (T, 32, 3) in centimetres → the template's (T, 22, 3) in metres."""
    p = np.asarray(mocap_positions, float)
    if p.ndim != 3 or p.shape[1:] != (len(NAMES), 3):
        raise ValueError(f"mocap_positions: expected (T, {len(NAMES)}, 3), got {p.shape}")
    return p[:, list(TEMPLATE_JOINTS)] / CM

TEMPLATE_TO_MOCAP = {JOINT_NAMES[j]: name for name, j in MOCAP_TO_TEMPLATE.items()}
"""The joint map (template joint name → mocap joint name) a retargeting step uses (joint_maps)."""
