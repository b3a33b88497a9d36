"""The HumanML3D vector of many clips at once — the same numbers as `motion.features.encode`.

`features.encode` handles one clip; most of its time goes to per-call overhead, which dominates a
corpus build of thousands of short clips. `encode_many` pads clips of similar length to a common
length by repeating their last frame (exact: the encoder's only cross-frame filter, a Gaussian over
time with edge mode "nearest", sees the same values), encodes the stack in one pass and cuts each
clip back to its T − 1 rows. A test checks it against `features.encode`.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d

from ..motion import features as F
from ..motion import rotations as rot
from ..motion.skeleton import KINEMATIC_CHAINS, REST_DIRECTIONS


def _root_rotations(p):
    """(B, T, 4) root quaternions as features.root_rotations computes them, per clip."""
    a, b, c, d = F.FACE_JOINTS
    across = rot.normalize((p[:, :, a] - p[:, :, b]) + (p[:, :, c] - p[:, :, d]))
    forward = np.cross(np.array([0.0, 1.0, 0.0]), across)
    forward = gaussian_filter1d(forward, F.FORWARD_SMOOTHING_SIGMA, axis=1, mode="nearest")
    forward = rot.normalize(forward)
    q = F.facing_to_z(forward)
    q[:, 0] = (1.0, 0.0, 0.0, 0.0)
    # rotations.quat_fix, vectorised: flip where the dot with the (already fixed) previous is < 0
    flips = np.where((q[:, 1:] * q[:, :-1]).sum(-1) < 0, -1.0, 1.0)
    sign = np.concatenate([np.ones((q.shape[0], 1)), np.cumprod(flips, axis=1)], axis=1)
    return q * sign[..., None]


def _chain_layout():
    """Children of the chains' bones in order, and each one's parent bone (−1: the chain's start,
    whose frame is the root rotation in features.chain_rotations)."""
    children, parent_bone = [], []
    for chain in KINEMATIC_CHAINS:
        for k, child in enumerate(chain[1:]):
            children.append(child)
            parent_bone.append(-1 if k == 0 else len(children) - 2)
    return np.array(children), np.array(parent_bone)


_CHILDREN, _PARENT_BONE = _chain_layout()


def _chain_rotations(p, root_quat):
    """(B, T, 22, 4) joint rotations as features.chain_rotations computes them: each bone's
    rest→observed rotation, made local to the previous bone of its chain (the root for the first)."""
    B, T = p.shape[:2]
    starts = np.array([chain[k] for chain in KINEMATIC_CHAINS for k in range(len(chain) - 1)])
    v = rot.normalize(p[:, :, _CHILDREN] - p[:, :, starts])
    u = np.broadcast_to(REST_DIRECTIONS[_CHILDREN], v.shape)
    glob = rot.quat_between(u, v)  # (B, T, 21, 4)
    frame = np.where((_PARENT_BONE < 0)[:, None], root_quat[:, :, None], glob[:, :, np.maximum(_PARENT_BONE, 0)])
    quats = np.zeros((B, T, F.N_JOINTS, 4))
    quats[..., 0] = 1.0
    quats[:, :, 0] = root_quat
    quats[:, :, _CHILDREN] = rot.quat_mul(rot.quat_inv(frame), glob)
    return quats


def _encode_stack(p) -> np.ndarray:
    """(B, T, 22, 3) positions → (B, T − 1, 263)."""
    B, T = p.shape[:2]
    r = _root_rotations(p)
    quats = _chain_rotations(p, r)
    step = rot.quat_mul(r[:, 1:], rot.quat_inv(r[:, :-1]))
    root_rot_vel = np.arcsin(np.clip(step[..., 2:3], -1, 1))
    root_vel = rot.quat_rotate(r[:, 1:], p[:, 1:, 0] - p[:, :-1, 0])[..., [0, 2]]
    root_y = p[:, :-1, 0, 1:2]
    centred = p.copy()
    centred[..., [0, 2]] -= p[:, :, :1, [0, 2]]
    r_rep = np.repeat(r[:, :, None], F.N_JOINTS, 2)
    ric = rot.quat_rotate(r_rep, centred)[:, :-1, 1:].reshape(B, T - 1, -1)
    rot6d = rot.quat_to_6d(quats[:, :-1, 1:]).reshape(B, T - 1, -1)
    local_vel = rot.quat_rotate(r_rep[:, :-1], p[:, 1:] - p[:, :-1]).reshape(B, T - 1, -1)
    feet = p[:, :, list(F.CONTACT_JOINTS)]
    contacts = (((feet[:, 1:] - feet[:, :-1]) ** 2).sum(-1) < F.CONTACT_THRESHOLD).astype(np.float64)
    out = np.concatenate([root_rot_vel, root_vel, root_y, ric, rot6d, local_vel, contacts], -1)
    return out.astype(np.float32)


def encode_many(positions_list, bucket: int = 16) -> list:
    """Encode many (T_i, 22, 3) clips; returns their (T_i − 1, 263) float32 vectors, in order.
    Clips are grouped by length rounded up to `bucket` frames and padded with their last frame."""
    arrays = [F.check_positions(p, f"positions_list[{i}]") for i, p in enumerate(positions_list)]
    out = [None] * len(arrays)
    keys = [int(np.ceil(len(a) / bucket) * bucket) for a in arrays]
    for key in sorted(set(keys)):
        idx = [i for i, k in enumerate(keys) if k == key]
        stack = np.stack([np.concatenate([arrays[i], np.repeat(arrays[i][-1:], key - len(arrays[i]), 0)])
                          for i in idx])
        enc = _encode_stack(stack)
        for j, i in enumerate(idx):
            out[i] = enc[j, :len(arrays[i]) - 1]
    return out
