"""The HumanML3D 263-d motion vector: encode positions, decode back, normalise (the release's conventions,
documented below).

Per frame t (T positions give T−1 rows, velocities need frame t+1):
    [0]        root angular velocity about Y — half the yaw step (arcsin of the step quaternion's y)
    [1:3]      root XZ velocity in the facing frame
    [3]        root height
    [4:67]     joints 1..21 relative to the root in XZ, in the facing frame ("ric")
    [67:193]   joints 1..21 local rotations, 6-D (HumanML3D's per-chain convention)
    [193:259]  22 joint velocities p[t+1] − p[t], in the facing frame of frame t
    [259:263]  foot contacts: left ankle, left foot, right ankle, right foot

`encode` expects canonical positions (reference body, floor at y = 0, initially facing +Z): frame 0's
root rotation is the identity by definition, as in the release.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from scipy.ndimage import gaussian_filter1d

from . import rotations as rot
from .skeleton import KINEMATIC_CHAINS, REST_DIRECTIONS

N_JOINTS = 22
N_FEATURES = 263
BLOCKS = {  # name → slice of the 263-d vector
    "root_rot_vel": slice(0, 1),
    "root_lin_vel": slice(1, 3),
    "root_y": slice(3, 4),
    "ric": slice(4, 67),
    "rot6d": slice(67, 193),
    "local_vel": slice(193, 259),
    "contacts": slice(259, 263),
}
TRAJECTORY_DIMS = slice(0, 3)  # what paper B's trajectory condition reads
CONTACT_JOINTS = (7, 10, 8, 11)
CONTACT_THRESHOLD = 0.002  # summed squared displacement per frame, m²
FACE_JOINTS = (1, 2, 17, 16)  # the IK path's face vector: (p1 − p2) + (p17 − p16) (the release's choice)
FORWARD_SMOOTHING_SIGMA = 20  # frames


def _lib(x):
    return torch if isinstance(x, torch.Tensor) else np


def check_positions(positions, name: str = "positions", min_frames: int = 2) -> np.ndarray:
    """Validate joint positions (T, 22, 3): finite, at least `min_frames` frames."""
    p = np.asarray(positions)
    if p.ndim != 3 or p.shape[1:] != (N_JOINTS, 3):
        raise ValueError(f"{name}: expected shape (T, {N_JOINTS}, 3), got {p.shape}")
    if p.shape[0] < min_frames:
        raise ValueError(f"{name}: need at least {min_frames} frames, got {p.shape[0]}")
    if not np.isfinite(p).all():
        raise ValueError(f"{name}: contains NaN or Inf values")
    return p.astype(np.float64)


def check_features(features, name: str = "features"):
    """Validate a 263-d feature array (..., T, 263) with finite values; returns it unchanged."""
    if features.ndim < 2 or features.shape[-1] != N_FEATURES:
        raise ValueError(f"{name}: expected shape (..., T, {N_FEATURES}), got {tuple(features.shape)}")
    if features.shape[-2] < 1:
        raise ValueError(f"{name}: has no frames")
    finite = torch.isfinite(features).all() if isinstance(features, torch.Tensor) else np.isfinite(features).all()
    if not bool(finite):
        raise ValueError(f"{name}: contains NaN or Inf values")
    return features


# ---------------------------------------------------------------- encoding pieces
def foot_contacts(positions, threshold: float = CONTACT_THRESHOLD) -> np.ndarray:
    """(T−1, 4) contacts of joints 7, 10, 8, 11: summed squared step below `threshold` (no height test)."""
    p = np.asarray(positions)[:, list(CONTACT_JOINTS)]
    step2 = ((p[1:] - p[:-1]) ** 2).sum(-1)
    return (step2 < threshold).astype(np.float32)


def facing_to_z(forward) -> np.ndarray:
    """(..., 4) yaw quaternions taking horizontal unit directions (..., 3) onto +Z."""
    q = rot.quat_between(forward, np.broadcast_to([0.0, 0.0, 1.0], forward.shape))
    # facing exactly −Z: any axis ⟂ Z turns it onto +Z and quat_between picks a horizontal one, which would
    # tip the body over; the facing rotation is a yaw, so take the half turn about Y
    q[1.0 + forward[..., 2] < 1e-7] = (0.0, 0.0, 1.0, 0.0)  # quat_between's own test for opposite directions
    return q


def root_rotations(positions) -> np.ndarray:
    """(T, 4) root quaternions taking the smoothed facing direction onto +Z; frame 0 = identity."""
    p = np.asarray(positions, dtype=np.float64)
    a, b, c, d = FACE_JOINTS
    across = (p[:, a] - p[:, b]) + (p[:, c] - p[:, d])  # the release's sign quirk
    across = rot.normalize(across)
    forward = np.cross(np.array([0.0, 1.0, 0.0]), across)
    forward = gaussian_filter1d(forward, FORWARD_SMOOTHING_SIGMA, axis=0, mode="nearest")
    forward = rot.normalize(forward)
    q = facing_to_z(forward)
    q[0] = (1.0, 0.0, 0.0, 0.0)
    return rot.quat_fix(q)


def chain_rotations(positions, root_quat) -> np.ndarray:
    """(T, 22, 4) HumanML3D joint rotations: per chain, the rest→observed bone rotation made local."""
    p = np.asarray(positions, dtype=np.float64)
    T = p.shape[0]
    quats = np.zeros((T, N_JOINTS, 4))
    quats[..., 0] = 1.0
    quats[:, 0] = root_quat
    for chain in KINEMATIC_CHAINS:
        R = root_quat
        for parent, child in zip(chain[:-1], chain[1:]):
            u = np.broadcast_to(REST_DIRECTIONS[child], (T, 3))
            v = rot.normalize(p[:, child] - p[:, parent])
            to_observed = rot.quat_between(u, v)  # rest direction → observed bone direction
            local = rot.quat_mul(rot.quat_inv(R), to_observed)
            quats[:, child] = local
            R = rot.quat_mul(R, local)
    return quats


def root_relative(positions, r_rot=None) -> np.ndarray:
    """(T, 21·3) joints 1..21 relative to the root's ground point, in each frame's facing frame."""
    p = np.asarray(positions, dtype=np.float64)
    r_rot = root_rotations(p) if r_rot is None else r_rot
    centred = p.copy()
    centred[..., [0, 2]] -= p[:, :1, [0, 2]]
    return rot.quat_rotate(np.repeat(r_rot[:, None], N_JOINTS, 1), centred)[:, 1:].reshape(len(p), -1)


def encode(positions) -> np.ndarray:
    """Canonical joint positions (T, 22, 3) → the HumanML3D vector (T−1, 263), float32."""
    p = check_positions(positions)
    T = p.shape[0]
    r_rot = root_rotations(p)  # (T, 4)
    quats = chain_rotations(p, r_rot)  # (T, 22, 4)

    # [0] half the yaw step: y of q[t+1] ⊗ q[t]⁻¹;  [1:3] root velocity in the facing frame of t+1
    step = rot.quat_mul(r_rot[1:], rot.quat_inv(r_rot[:-1]))
    root_rot_vel = np.arcsin(np.clip(step[:, 2:3], -1, 1))
    root_vel = rot.quat_rotate(r_rot[1:], p[1:, 0] - p[:-1, 0])[:, [0, 2]]
    root_y = p[:-1, 0, 1:2]

    ric = root_relative(p, r_rot)[:-1]  # [4:67]

    rot6d = rot.quat_to_6d(quats[:-1, 1:]).reshape(T - 1, -1)
    local_vel = rot.quat_rotate(np.repeat(r_rot[:-1, None], N_JOINTS, 1), p[1:] - p[:-1]).reshape(T - 1, -1)
    contacts = foot_contacts(p)
    out = np.concatenate([root_rot_vel, root_vel, root_y, ric, rot6d, local_vel, contacts], axis=-1)
    return out.astype(np.float32)


# ---------------------------------------------------------------- decoding ("recover from ric")
def recover_root(features):
    """Root quaternions (..., T, 4) and root positions (..., T, 3) from features (..., T, 263)."""
    lib = _lib(features)
    half_yaw = features[..., 0]
    # a[0] = 0, a[t] = Σ_{s<t} data[s, 0]
    angle = lib.zeros_like(half_yaw)
    angle[..., 1:] = half_yaw[..., :-1]
    angle = angle.cumsum(-1) if lib is torch else np.cumsum(angle, -1)
    zero = lib.zeros_like(angle)
    q = lib.stack([lib.cos(angle), zero, lib.sin(angle), zero], -1)
    # r[0] = 0, r[t] = Σ_{s=1..t} q_s⁻¹ · (vx[s−1], 0, vz[s−1])
    vel = lib.zeros_like(features[..., :3])
    vel[..., 1:, 0] = features[..., :-1, 1]
    vel[..., 1:, 2] = features[..., :-1, 2]
    vel = rot.quat_rotate(rot.quat_inv(q), vel)
    root = vel.cumsum(-2) if lib is torch else np.cumsum(vel, -2)
    root[..., 1] = features[..., 3]
    return q, root


def decode(features):
    """The HumanML3D vector (..., T, 263) → joint positions (..., T, 22, 3); numpy or torch."""
    check_features(features)
    lib = _lib(features)
    q, root = recover_root(features)
    ric = features[..., BLOCKS["ric"]].reshape(*features.shape[:-1], N_JOINTS - 1, 3)
    q_rep = q[..., None, :].expand(*ric.shape[:-1], 4) if lib is torch else \
        np.broadcast_to(q[..., None, :], (*ric.shape[:-1], 4))
    joints = rot.quat_rotate(rot.quat_inv(q_rep), ric)
    offset = lib.zeros_like(root)
    offset[..., 0], offset[..., 2] = root[..., 0], root[..., 2]
    joints = joints + offset[..., None, :]
    cat = torch.cat if lib is torch else np.concatenate
    return cat([root[..., None, :], joints], -2)


# ---------------------------------------------------------------- normalisation
def block_averaged_std(std) -> np.ndarray:
    """Average a 263-d std within each block, as the release does."""
    std = np.asarray(std, dtype=np.float64).copy()
    for sl in BLOCKS.values():
        std[sl] = std[sl].mean()
    return std


class Normalizer:
    """(x − mean) / std over the 263 dims, with the std averaged per block, as the release does."""

    def __init__(self, mean, std, eps: float = 1e-8):
        mean, std = np.asarray(mean, np.float32), np.asarray(std, np.float32)
        if mean.shape != (N_FEATURES,) or std.shape != (N_FEATURES,):
            raise ValueError(f"Normalizer: mean and std must have shape ({N_FEATURES},), "
                             f"got {mean.shape} and {std.shape}")
        if not (np.isfinite(mean).all() and np.isfinite(std).all()) or (std < 0).any():
            raise ValueError("Normalizer: mean/std must be finite and std non-negative")
        self.mean, self.std = mean, np.maximum(std, eps).astype(np.float32)

    @classmethod
    def fit(cls, feature_arrays) -> "Normalizer":
        """Mean and block-averaged std over all frames of a list of (T, 263) arrays."""
        arrays = [check_features(np.asarray(a), f"feature_arrays[{i}]") for i, a in enumerate(feature_arrays)]
        if not arrays:
            raise ValueError("Normalizer.fit: feature_arrays is empty")
        allf = np.concatenate(arrays, 0).astype(np.float64)
        return cls(allf.mean(0), block_averaged_std(allf.std(0)))

    @classmethod
    def load(cls, folder) -> "Normalizer":
        """Read mean.npy and std.npy (or the release's Mean.npy/Std.npy) from a folder."""
        folder = Path(folder)
        for m, s in (("mean.npy", "std.npy"), ("Mean.npy", "Std.npy")):
            if (folder / m).is_file() and (folder / s).is_file():
                return cls(np.load(folder / m), np.load(folder / s))
        raise ValueError(f"{folder}: no mean.npy/std.npy (or Mean.npy/Std.npy) found")

    def save(self, folder) -> None:
        """Write mean.npy and std.npy into a folder."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        np.save(folder / "mean.npy", self.mean)
        np.save(folder / "std.npy", self.std)

    def _stats(self, x):
        if isinstance(x, torch.Tensor):
            return (torch.as_tensor(self.mean, dtype=x.dtype, device=x.device),
                    torch.as_tensor(self.std, dtype=x.dtype, device=x.device))
        return self.mean, self.std

    def normalize(self, x):
        """(x − mean) / std."""
        check_features(x, "x")
        mean, std = self._stats(x)
        return (x - mean) / std

    def denormalize(self, x):
        """x · std + mean."""
        check_features(x, "x")
        mean, std = self._stats(x)
        return x * std + mean
