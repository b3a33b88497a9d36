"""Fast batched rotation algebra and forward kinematics in a structure-of-arrays layout.

numpy multiplies stacks of 3×3 matrices one small matrix at a time; the generator multiplies
hundreds of thousands of them. Here a stack of N rotations is stored as (3, 3, N) — entry (i, j)
of every matrix contiguous — and a stack of vectors as (3, N), so each product is a handful of
long vectorised multiply-adds. Results equal `skeleton.forward_kinematics` to rounding.
"""
from __future__ import annotations

import numpy as np


def mm(a, b):
    """Products a·b of matrix stacks (3, 3, ...)."""
    return a[:, 0, None] * b[None, 0] + a[:, 1, None] * b[None, 1] + a[:, 2, None] * b[None, 2]


def mv(a, v):
    """Matrix stack (3, 3, ...) applied to vectors (3, ...)."""
    return a[:, 0] * v[0] + a[:, 1] * v[1] + a[:, 2] * v[2]


def tr(a):
    """Transposes of a matrix stack (3, 3, ...)."""
    return a.swapaxes(0, 1)


def to_soa(M):
    """(N, 3, 3) → (3, 3, N); (N, J, 3, 3) → (J, 3, 3, N)."""
    M = np.asarray(M)
    return np.ascontiguousarray(M.transpose(1, 2, 0) if M.ndim == 3 else M.transpose(1, 2, 3, 0))


def from_soa(S):
    """(3, 3, N) → (N, 3, 3); (J, 3, 3, N) → (N, J, 3, 3)."""
    S = np.asarray(S)
    return np.ascontiguousarray(S.transpose(2, 0, 1) if S.ndim == 3 else S.transpose(3, 0, 1, 2))


def euler_pyr(angles_deg) -> np.ndarray:
    """(N, J, 3) (pitch, yaw, roll) degrees → Rx(pitch)·Rz(roll)·Ry(yaw) as (J, 3, 3, N)."""
    a = np.deg2rad(np.asarray(angles_deg, float).transpose(1, 2, 0))  # (J, 3, N)
    c, s = np.cos(a), np.sin(a)
    ca, cb, cc = c[:, 0], c[:, 1], c[:, 2]
    sa, sb, sc = s[:, 0], s[:, 1], s[:, 2]
    out = np.empty((a.shape[0], 3, 3, a.shape[2]))
    sccb, scsb = sc * cb, sc * sb
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = cc * cb, -sc, cc * sb
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = ca * sccb + sa * sb, ca * cc, ca * scsb - sa * cb
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = sa * sccb - ca * sb, sa * cc, sa * scsb + ca * cb
    return out


def yaw_pitch(yaw, pitch) -> np.ndarray:
    """Ry(yaw)·Rx(pitch) (radians) as (3, 3, N)."""
    cb, sb, ca, sa = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
    z = np.zeros_like(cb)
    return np.array([[cb, sb * sa, sb * ca], [z, ca, -sa], [-sb, cb * sa, cb * ca]])


def rot_y(yaw) -> np.ndarray:
    """Ry(yaw) (radians) as (3, 3, N)."""
    return yaw_pitch(yaw, np.zeros_like(np.asarray(yaw, float)))


def between(a, b) -> np.ndarray:
    """Shortest-arc rotations (3, 3, N) taking unit vectors a (3, N) onto unit vectors b."""
    v = np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    k = 1.0 / np.maximum(1.0 + (a * b).sum(0), 1e-9)
    s = 1.0 - (v * v).sum(0) * k
    z = np.zeros_like(k)
    K = np.array([[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]])
    out = K + v[:, None] * v[None, :] * k
    for i in range(3):
        out[i, i] += s
    return out


def fk(parents, offsets, R, root, return_globals: bool = False):
    """Forward kinematics. offsets (J, 3), or per frame (J, 3, N); R (J, 3, 3, N); root (N, 3).

    Returns positions (N, J, 3) and, if asked, global rotations (J, 3, 3, N)."""
    J, N = R.shape[0], R.shape[-1]
    off = np.asarray(offsets, float)
    if off.shape[:2] != (J, 3) or off.ndim not in (2, 3):
        raise ValueError(f"offsets: expected ({J}, 3) or ({J}, 3, N), got {off.shape}")
    off = off[:, :, None] if off.ndim == 2 else off
    G = np.empty_like(R)
    pos = np.empty((J, 3, N))
    for j, p in enumerate(parents):
        if p < 0:
            G[j] = R[j]
            pos[j] = np.ascontiguousarray(np.asarray(root, float).T)
            continue
        pos[j] = pos[p] + mv(G[p], off[j])
        G[j] = mm(G[p], R[j])
    positions = np.ascontiguousarray(pos.transpose(2, 0, 1))
    return (positions, G) if return_globals else positions
