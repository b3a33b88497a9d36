"""Rotation conversions for numpy arrays and torch tensors alike, batched over leading axes.

Conventions (the HumanML3D ones):
- quaternions are (w, x, y, z), unit length, acting on column vectors: v' = q v q*;
- matrices act on column vectors (v' = R v), shape (..., 3, 3);
- 6-D form = the first two columns of the matrix, concatenated: (R[:,0], R[:,1]);
- axis-angle = axis * angle (radians), shape (..., 3);
- Euler angles are intrinsic, in the order given ("ZYX" means R = Rz(a0) · Ry(a1) · Rx(a2)),
  which is how a BVH channel list "Zrotation Yrotation Xrotation" composes.

Every function takes numpy or torch and returns the same kind; numpy Euler conversions use scipy.
"""
from __future__ import annotations

import numpy as np
import torch

_AXES = {"X": 0, "Y": 1, "Z": 2}


# ---------------------------------------------------------------- backend helpers
def _is_torch(x) -> bool:
    return isinstance(x, torch.Tensor)


def _stack(xs, axis, like):
    return torch.stack(xs, dim=axis) if _is_torch(like) else np.stack(xs, axis=axis)


def _cat(xs, axis, like):
    return torch.cat(xs, dim=axis) if _is_torch(like) else np.concatenate(xs, axis=axis)


def _norm(x, keepdims=True):
    if _is_torch(x):
        return torch.linalg.norm(x, dim=-1, keepdim=keepdims)
    return np.linalg.norm(x, axis=-1, keepdims=keepdims)


def _clip(x, lo, hi):
    return x.clamp(lo, hi) if _is_torch(x) else np.clip(x, lo, hi)


def _lib(x):
    return torch if _is_torch(x) else np


def _cross(a, b):
    return torch.linalg.cross(a, b, dim=-1) if _is_torch(a) else np.cross(a, b)


def _check_last(x, n: int, name: str):
    if x.shape[-1] != n:
        raise ValueError(f"{name}: expected last axis of size {n}, got shape {tuple(x.shape)}")


def normalize(v, eps: float = 1e-8):
    """v / |v| along the last axis (zero vectors stay zero)."""
    return v / _clip(_norm(v), eps, None)


# ---------------------------------------------------------------- quaternions
def quat_identity(shape=(), like=None):
    """Identity quaternions of the given batch shape (numpy unless `like` is a tensor)."""
    if like is not None and _is_torch(like):
        q = torch.zeros(*shape, 4, dtype=like.dtype, device=like.device)
    else:
        q = np.zeros((*shape, 4), dtype=np.float64 if like is None else like.dtype)
    q[..., 0] = 1
    return q


def quat_mul(a, b):
    """Hamilton product a ⊗ b (apply b first, then a)."""
    _check_last(a, 4, "quat_mul a")
    _check_last(b, 4, "quat_mul b")
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return _stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ], -1, a)


def quat_conj(q):
    """Conjugate = inverse for unit quaternions."""
    _check_last(q, 4, "quat_conj")
    sign = q.new_tensor([1, -1, -1, -1]) if _is_torch(q) else np.array([1, -1, -1, -1], q.dtype)
    return q * sign


quat_inv = quat_conj


def quat_rotate(q, v):
    """Rotate vectors v (..., 3) by unit quaternions q (..., 4): v + 2w(u×v) + 2u×(u×v)."""
    _check_last(q, 4, "quat_rotate q")
    _check_last(v, 3, "quat_rotate v")
    w, u = q[..., :1], q[..., 1:]
    t = 2 * _cross(u, v)
    return v + w * t + _cross(u, t)


def quat_between(u, v):
    """The shortest-arc unit quaternion rotating direction u onto direction v."""
    u, v = normalize(u), normalize(v)
    w = 1 + (u * v).sum(-1)[..., None]  # = 2cos²(θ/2) before normalising
    xyz = _cross(u, v)
    q = _cat([w, xyz], -1, u)
    # u = -v: any axis orthogonal to u does; pick one from the smallest component of u.
    lib = _lib(u)
    opposite = (w[..., 0] < 1e-7)
    if bool(opposite.any()):
        helper = lib.zeros_like(u)
        idx = lib.argmin(lib.abs(u), -1) if _is_torch(u) else np.argmin(np.abs(u), -1)
        if _is_torch(u):
            helper.scatter_(-1, idx[..., None], 1.0)
        else:
            np.put_along_axis(helper, idx[..., None], 1.0, axis=-1)
        axis = normalize(_cross(u, helper))
        q_opp = _cat([lib.zeros_like(w), axis], -1, u)
        q = lib.where(opposite[..., None], q_opp, q)
    return normalize(q)


def quat_fix(q):
    """Make a quaternion sequence (T, ..., 4) continuous over time by flipping signs."""
    q = q.clone() if _is_torch(q) else q.copy()
    for t in range(1, q.shape[0]):
        dot = (q[t] * q[t - 1]).sum(-1)
        flip = dot < 0
        q[t][flip] = -q[t][flip]
    return q


def quat_slerp(a, b, t):
    """Spherical interpolation from a to b at fraction t (broadcast over the batch)."""
    lib = _lib(a)
    dot = (a * b).sum(-1)
    b = lib.where((dot < 0)[..., None], -b, b)
    dot = lib.abs(dot)
    t = t if not isinstance(t, (int, float)) else (a[..., 0] * 0 + t)
    theta = lib.arccos(_clip(dot, -1.0, 1.0)) if not _is_torch(a) else torch.acos(dot.clamp(-1, 1))
    sin = lib.sin(theta)
    small = sin < 1e-6
    safe = lib.where(small, lib.ones_like(sin), sin)
    wa = lib.where(small, 1 - t, lib.sin((1 - t) * theta) / safe)
    wb = lib.where(small, t, lib.sin(t * theta) / safe)
    return normalize(wa[..., None] * a + wb[..., None] * b)


# ---------------------------------------------------------------- matrices
def quat_to_matrix(q):
    """(..., 4) unit quaternions → (..., 3, 3) rotation matrices."""
    _check_last(q, 4, "quat_to_matrix")
    q = normalize(q)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = [
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ]
    m = _stack(rows, -1, q)
    return m.reshape(*q.shape[:-1], 3, 3)


def matrix_to_quat(m):
    """(..., 3, 3) rotation matrices → (..., 4) unit quaternions with w ≥ 0 (Shepperd's method)."""
    if tuple(m.shape[-2:]) != (3, 3):
        raise ValueError(f"matrix_to_quat: expected (..., 3, 3), got shape {tuple(m.shape)}")
    lib = _lib(m)
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    # four candidates, each well conditioned when its leading component is large
    trace_terms = _stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22,
                          1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1, m)
    best = lib.argmax(trace_terms, -1) if _is_torch(m) else np.argmax(trace_terms, -1)
    s = lib.sqrt(_clip(trace_terms, 1e-12, None)) * 2  # = 4·|leading component|
    cands = [
        [s[..., 0] / 4, (m[..., 2, 1] - m[..., 1, 2]) / s[..., 0],
         (m[..., 0, 2] - m[..., 2, 0]) / s[..., 0], (m[..., 1, 0] - m[..., 0, 1]) / s[..., 0]],
        [(m[..., 2, 1] - m[..., 1, 2]) / s[..., 1], s[..., 1] / 4,
         (m[..., 0, 1] + m[..., 1, 0]) / s[..., 1], (m[..., 0, 2] + m[..., 2, 0]) / s[..., 1]],
        [(m[..., 0, 2] - m[..., 2, 0]) / s[..., 2], (m[..., 0, 1] + m[..., 1, 0]) / s[..., 2],
         s[..., 2] / 4, (m[..., 1, 2] + m[..., 2, 1]) / s[..., 2]],
        [(m[..., 1, 0] - m[..., 0, 1]) / s[..., 3], (m[..., 0, 2] + m[..., 2, 0]) / s[..., 3],
         (m[..., 1, 2] + m[..., 2, 1]) / s[..., 3], s[..., 3] / 4],
    ]
    cands = _stack([_stack(c, -1, m) for c in cands], -2, m)  # (..., 4 candidates, 4)
    if _is_torch(m):
        q = torch.gather(cands, -2, best[..., None, None].expand(*best.shape, 1, 4))[..., 0, :]
    else:
        q = np.take_along_axis(cands, best[..., None, None], axis=-2)[..., 0, :]
    q = lib.where(q[..., :1] < 0, -q, q)
    return normalize(q)


def matrix_to_6d(m):
    """(..., 3, 3) → (..., 6): the first two columns, column 0 then column 1."""
    return _cat([m[..., :, 0], m[..., :, 1]], -1, m)


def sixd_to_matrix(d6):
    """(..., 6) → (..., 3, 3) by Gram–Schmidt on the two stored columns."""
    _check_last(d6, 6, "sixd_to_matrix")
    a1, a2 = d6[..., :3], d6[..., 3:]
    c0 = normalize(a1)
    c2 = normalize(_cross(c0, a2))
    c1 = _cross(c2, c0)
    return _stack([c0, c1, c2], -1, d6)


def quat_to_6d(q):
    """(..., 4) → (..., 6)."""
    return matrix_to_6d(quat_to_matrix(q))


def sixd_to_quat(d6):
    """(..., 6) → (..., 4)."""
    return matrix_to_quat(sixd_to_matrix(d6))


# ---------------------------------------------------------------- axis-angle
def axis_angle_to_quat(aa):
    """(..., 3) axis·angle → (..., 4)."""
    _check_last(aa, 3, "axis_angle_to_quat")
    lib = _lib(aa)
    angle = _norm(aa)
    half = angle / 2
    # sin(half)/angle → 1/2 as angle → 0 (Taylor) keeps small rotations exact
    small = angle < 1e-6
    safe = lib.where(small, lib.ones_like(angle), angle)
    k = lib.where(small, 0.5 - angle * angle / 48, lib.sin(half) / safe)
    return _cat([lib.cos(half), aa * k], -1, aa)


def quat_to_axis_angle(q):
    """(..., 4) → (..., 3) axis·angle with angle in [0, π]."""
    _check_last(q, 4, "quat_to_axis_angle")
    lib = _lib(q)
    q = lib.where(q[..., :1] < 0, -q, q)
    xyz_norm = _norm(q[..., 1:])
    angle = 2 * lib.arctan2(xyz_norm, q[..., :1]) if not _is_torch(q) else 2 * torch.atan2(xyz_norm, q[..., :1])
    small = xyz_norm < 1e-6
    safe = lib.where(small, lib.ones_like(xyz_norm), xyz_norm)
    k = lib.where(small, 2 / _clip(q[..., :1], 1e-6, None), angle / safe)  # angle/sin(angle/2) → 2/w
    return q[..., 1:] * k


def axis_angle_to_matrix(aa):
    """(..., 3) → (..., 3, 3)."""
    return quat_to_matrix(axis_angle_to_quat(aa))


def matrix_to_axis_angle(m):
    """(..., 3, 3) → (..., 3)."""
    return quat_to_axis_angle(matrix_to_quat(m))


# ---------------------------------------------------------------- Euler (intrinsic, any order)
def _check_order(order: str) -> str:
    o = str(order).upper()
    if len(o) != 3 or set(o) - set("XYZ") or len(set(o)) != 3:
        raise ValueError(f"Euler order must be a permutation of 'XYZ' (e.g. 'ZYX'), got {order!r}")
    return o


def _axis_matrix(axis: int, angle):
    lib = _lib(angle)
    c, s = lib.cos(angle), lib.sin(angle)
    one, zero = lib.ones_like(angle), lib.zeros_like(angle)
    if axis == 0:
        rows = [one, zero, zero, zero, c, -s, zero, s, c]
    elif axis == 1:
        rows = [c, zero, s, zero, one, zero, -s, zero, c]
    else:
        rows = [c, -s, zero, s, c, zero, zero, zero, one]
    return _stack(rows, -1, angle).reshape(*angle.shape, 3, 3)


def euler_to_matrix(angles, order: str, degrees: bool = False):
    """(..., 3) intrinsic Euler angles in `order` → (..., 3, 3); R = R_order[0] · R_order[1] · R_order[2]."""
    _check_last(angles, 3, "euler_to_matrix")
    order = _check_order(order)
    if not _is_torch(angles):
        from scipy.spatial.transform import Rotation
        flat = np.asarray(angles, dtype=np.float64).reshape(-1, 3)
        m = Rotation.from_euler(order, flat, degrees=degrees).as_matrix()
        return m.reshape(*angles.shape[:-1], 3, 3)
    a = torch.deg2rad(angles) if degrees else angles
    m = _axis_matrix(_AXES[order[0]], a[..., 0])
    for k in (1, 2):
        m = m @ _axis_matrix(_AXES[order[k]], a[..., k])
    return m


def matrix_to_euler(m, order: str, degrees: bool = False):
    """(..., 3, 3) → (..., 3) intrinsic Euler angles in `order` (middle angle in [−π/2, π/2])."""
    order = _check_order(order)
    if not _is_torch(m):
        from scipy.spatial.transform import Rotation
        flat = np.asarray(m, dtype=np.float64).reshape(-1, 3, 3)
        e = Rotation.from_matrix(flat).as_euler(order, degrees=degrees)
        return e.reshape(*m.shape[:-2], 3)
    i, j, k = (_AXES[c] for c in order)
    sign = 1.0 if (i, j, k) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
    a1 = torch.asin((sign * m[..., i, k]).clamp(-1, 1))
    a0 = torch.atan2(-sign * m[..., j, k], m[..., k, k])
    a2 = torch.atan2(-sign * m[..., i, j], m[..., i, i])
    e = torch.stack([a0, a1, a2], -1)
    return torch.rad2deg(e) if degrees else e


def euler_to_quat(angles, order: str, degrees: bool = False):
    """(..., 3) Euler → (..., 4)."""
    return matrix_to_quat(euler_to_matrix(angles, order, degrees))


def quat_to_euler(q, order: str, degrees: bool = False):
    """(..., 4) → (..., 3) Euler."""
    return matrix_to_euler(quat_to_matrix(q), order, degrees)
