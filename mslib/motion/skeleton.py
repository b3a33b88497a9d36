"""Skeletons and forward kinematics; the HumanML3D 22-joint template.

A `Skeleton` is a joint tree: names, parent indices (parents before children) and rest offsets
(each joint's position relative to its parent in the rest pose). Forward kinematics follows the
BVH convention: a joint's local rotation turns the offsets of its children,
    G[j] = G[parent(j)] · R[j],   p[j] = p[parent(j)] + G[parent(j)] · offset[j].
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch

from . import rotations as rot

# ---------------------------------------------------------------- the HumanML3D template
JOINT_NAMES = (
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
    "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar",
    "right_collar", "head", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
    "left_wrist", "right_wrist",
)
PARENTS = (-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19)
KINEMATIC_CHAINS = ((0, 2, 5, 8, 11), (0, 1, 4, 7, 10), (0, 3, 6, 9, 12, 15),
                    (9, 14, 17, 19, 21), (9, 13, 16, 18, 20))
# unit rest directions, joint from parent; +X is the character's left
REST_DIRECTIONS = np.array([
    [0, 0, 0], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, -1, 0], [0, 1, 0], [0, -1, 0],
    [0, -1, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1],
    [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0]], dtype=np.float64)
# the reference body's bone lengths in metres, joints 1..21 (HumanML3D rescales every motion to it)
REFERENCE_BONE_LENGTHS = np.array([
    0.1031, 0.1099, 0.1316, 0.3936, 0.3902, 0.1432, 0.4324, 0.4256, 0.0574, 0.1434, 0.1494,
    0.2194, 0.1375, 0.1434, 0.1030, 0.1316, 0.1230, 0.2568, 0.2631, 0.2660, 0.2699])
# 7/8 left ankle/foot, 8/11 right ankle/foot
FOOT_JOINTS_LEFT = (7, 10)
FOOT_JOINTS_RIGHT = (8, 11)
# joint i ↔ MIRROR[i] under a left/right swap
MIRROR = (0, 2, 1, 3, 5, 4, 6, 8, 7, 9, 11, 10, 12, 14, 13, 15, 17, 16, 19, 18, 21, 20)


@dataclass(frozen=True)
class Skeleton:
    """A joint tree: names, parents (parent index < child index, root −1) and rest offsets (J, 3)."""

    names: tuple
    parents: tuple
    offsets: np.ndarray = field(repr=False)

    def __post_init__(self):
        n = len(self.names)
        offsets = np.asarray(self.offsets, dtype=np.float64)
        if len(self.parents) != n or offsets.shape != (n, 3):
            raise ValueError(f"Skeleton: {n} names, {len(self.parents)} parents and offsets of shape "
                             f"{offsets.shape} do not agree (expected ({n}, 3))")
        for j, p in enumerate(self.parents):
            if (j == 0) != (p == -1) or p >= j:
                raise ValueError(f"Skeleton: joint {j} ({self.names[j]}) has parent {p}; the root must "
                                 "come first and every parent before its children")
        object.__setattr__(self, "offsets", offsets)

    @property
    def n_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of a joint by name."""
        try:
            return self.names.index(name)
        except ValueError:
            raise ValueError(f"no joint named {name!r}; joints are {list(self.names)}") from None

    def children(self, j: int) -> list[int]:
        """Indices of the joints whose parent is j."""
        return [c for c, p in enumerate(self.parents) if p == j]

    def bone_lengths(self) -> np.ndarray:
        """|offset| per joint (0 for the root)."""
        return np.linalg.norm(self.offsets, axis=-1)

    def rest_positions(self) -> np.ndarray:
        """Global joint positions in the rest pose, root at the origin, (J, 3)."""
        return forward_kinematics(self, np.broadcast_to(np.eye(3), (self.n_joints, 3, 3)), np.zeros(3))

    def scaled(self, factors) -> "Skeleton":
        """The same tree with each offset multiplied by a factor (scalar or one per joint)."""
        f = np.broadcast_to(np.asarray(factors, dtype=np.float64), (self.n_joints,))
        return Skeleton(self.names, self.parents, self.offsets * f[:, None])


def humanml3d_skeleton(bone_lengths=None) -> Skeleton:
    """The HumanML3D 22-joint template; bone lengths default to the reference body."""
    lengths = REFERENCE_BONE_LENGTHS if bone_lengths is None else np.asarray(bone_lengths, np.float64)
    if lengths.shape != (21,):
        raise ValueError(f"bone_lengths: expected 21 values (joints 1..21), got shape {lengths.shape}")
    offsets = REST_DIRECTIONS * np.concatenate([[0.0], lengths])[:, None]
    return Skeleton(JOINT_NAMES, PARENTS, offsets)


HUMANML3D = humanml3d_skeleton()


def forward_kinematics(skeleton: Skeleton, local_rotations, root_positions, offsets=None,
                       return_global_rotations: bool = False):
    """Joint positions (..., J, 3) from local rotations and root positions.

    local_rotations: (..., J, 3, 3) matrices or (..., J, 4) quaternions (w, x, y, z).
    root_positions: (..., 3). offsets: (J, 3) or (..., J, 3) to override the skeleton's (e.g. a
    per-clip body). numpy in → numpy out; torch in → torch out (differentiable).
    """
    is_torch = isinstance(local_rotations, torch.Tensor)
    R = local_rotations
    if R.shape[-1] == 4:
        R = rot.quat_to_matrix(R)
    if R.shape[-3:] != (skeleton.n_joints, 3, 3):
        raise ValueError(f"local_rotations: expected (..., {skeleton.n_joints}, 3, 3) or "
                         f"(..., {skeleton.n_joints}, 4), got {tuple(local_rotations.shape)}")
    off = skeleton.offsets if offsets is None else offsets
    if is_torch:
        off = torch.as_tensor(off, dtype=R.dtype, device=R.device)
        root_positions = torch.as_tensor(root_positions, dtype=R.dtype, device=R.device)
    else:
        off = np.asarray(off, dtype=np.float64)
    glob, pos = [None] * skeleton.n_joints, [None] * skeleton.n_joints
    for j, p in enumerate(skeleton.parents):
        if p < 0:
            glob[j], pos[j] = R[..., j, :, :], root_positions + 0 * R[..., j, :, 0]
            continue
        pos[j] = pos[p] + (glob[p] @ off[..., j, :, None])[..., 0]
        glob[j] = glob[p] @ R[..., j, :, :]
    stack = torch.stack if is_torch else np.stack
    positions = stack(pos, -2)
    return (positions, stack(glob, -3)) if return_global_rotations else positions


def positions_bone_lengths(positions, parents) -> np.ndarray:
    """Per-frame bone lengths (..., J) of joint positions (..., J, 3); 0 for the root."""
    positions = np.asarray(positions)
    par = np.array([max(p, 0) for p in parents])
    return np.linalg.norm(positions - positions[..., par, :], axis=-1)


def mirror_positions(positions):
    """Mirror template positions (..., 22, 3): negate X and swap left and right joints."""
    out = positions[..., list(MIRROR), :]
    out = out.clone() if isinstance(out, torch.Tensor) else out.copy()
    out[..., 0] = -out[..., 0]
    return out
