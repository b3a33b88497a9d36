"""Joint positions → local rotations on the template tree: the inverse of forward kinematics.

The 263-d vector and every method output are joint positions (T, 22, 3). To write them as BVH we
solve, frame by frame, the local rotation of every joint of the HumanML3D tree (skeleton.py):
- a joint with one child (knees, elbows, the spine …) turns its rest bone onto the observed bone by
  the shortest arc *in its parent's frame*, so it adds no twist of its own (twist about a bone is
  not visible in positions);
- a joint with several children (pelvis: both hips and spine1; spine3: neck and both collars) takes
  the rotation that best fits all its child bones at once (orthogonal Procrustes / Kabsch, via SVD);
- leaves (feet, head, wrists) keep the identity.
The rest offsets are fitted to the clip: every bone gets its median observed length, and the child
offsets of a branching joint get the clip's mean shape (aligned to the template's directions), so a
rigid body — any registered or HumanML3D motion — is reproduced exactly; only a body whose bone
lengths change over time (a network output) leaves a residual, which `fit_error` reports.
"""
from __future__ import annotations

import numpy as np

from . import rotations as rot
from .bvh import BVHMotion
from .features import check_positions
from .skeleton import JOINT_NAMES, PARENTS, REST_DIRECTIONS, Skeleton

END_SITE_FRACTION = 0.5  # an End Site continues a leaf's own bone by half its length (for viewers)
UNITS = {"m": 1.0, "cm": 100.0}


def _children(parents) -> list:
    kids = [[] for _ in parents]
    for j, p in enumerate(parents):
        if p >= 0:
            kids[p].append(j)
    return kids


def kabsch(rest, observed) -> np.ndarray:
    """Rotations (T, 3, 3) that best turn rest vectors (k, 3) onto observed vectors (T, k, 3)."""
    H = np.einsum("ki,tkj->tij", rest, observed)  # (T, 3, 3) Σ rest ⊗ observed
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.swapaxes(Vt, 1, 2) @ np.swapaxes(U, 1, 2)))
    D = np.zeros_like(H)
    D[:, 0, 0], D[:, 1, 1], D[:, 2, 2] = 1.0, 1.0, np.where(d == 0, 1.0, d)
    return np.swapaxes(Vt, 1, 2) @ D @ np.swapaxes(U, 1, 2)  # R = V D Uᵀ, R·rest ≈ observed


def fit_offsets(positions, parents=PARENTS, rest_directions=REST_DIRECTIONS) -> np.ndarray:
    """Rest offsets (J, 3) for a clip: median bone lengths along the rest directions, and at each
    branching joint the clip's mean child shape, rotated to best match the rest directions."""
    p = check_positions(positions)
    bones = p - p[:, [max(q, 0) for q in parents]]  # (T, J, 3), the root's is 0
    lengths = np.median(np.linalg.norm(bones, axis=-1), axis=0)  # (J,)
    offsets = np.asarray(rest_directions, np.float64) * lengths[:, None]
    for j, kids in enumerate(_children(parents)):
        if len(kids) < 2:
            continue
        template = offsets[kids]  # (k, 3)
        R = kabsch(template, bones[:, kids])  # (T, 3, 3)
        shape = np.einsum("tji,tkj->ki", R, bones[:, kids]) / len(p)  # mean of Rᵀ·bones, (k, 3)
        Q = kabsch(shape, template[None])[0]  # align the mean shape back onto the template
        offsets[kids] = shape @ Q.T
    return offsets


def solve_rotations(positions, offsets, parents=PARENTS) -> np.ndarray:
    """Local rotations (T, J, 3, 3) that put a skeleton with rest `offsets` onto `positions` (T, J, 3)."""
    p = np.asarray(positions, np.float64)
    T, J = p.shape[:2]
    local = np.tile(np.eye(3), (T, J, 1, 1))
    glob = np.empty((T, J, 3, 3))
    kids = _children(parents)
    for j in range(J):
        par = parents[j]
        G_par = np.broadcast_to(np.eye(3), (T, 3, 3)) if par < 0 else glob[:, par]
        if len(kids[j]) > 1:
            G = kabsch(offsets[kids[j]], p[:, kids[j]] - p[:, j:j + 1])
            local[:, j] = np.swapaxes(G_par, 1, 2) @ G
        elif len(kids[j]) == 1:
            c = kids[j][0]
            seen = np.einsum("tji,tj->ti", G_par, p[:, c] - p[:, j])  # the bone in the parent's frame
            local[:, j] = rot.quat_to_matrix(rot.quat_between(np.broadcast_to(offsets[c], seen.shape), seen))
        glob[:, j] = G_par @ local[:, j]
    return local


def positions_to_bvh(positions, fps: float = 20.0, units: str = "m", rotation_order: str = "ZYX",
                     name: str = "positions") -> BVHMotion:
    """Joint positions (T, 22, 3) in metres → a BVH motion on the template tree (root: 6 channels,
    other joints: 3 Euler channels), lengths in `units` ("m" or "cm")."""
    if units not in UNITS:
        raise ValueError(f"units: expected one of {sorted(UNITS)}, got {units!r}")
    p = check_positions(positions, name) * UNITS[units]
    offsets = fit_offsets(p)
    skeleton = Skeleton(JOINT_NAMES, PARENTS, offsets)
    local = solve_rotations(p, offsets)
    leaves = [j for j, k in enumerate(_children(PARENTS)) if not k]
    sites = {j: END_SITE_FRACTION * offsets[j] for j in leaves}
    return BVHMotion.from_arrays(skeleton, local, p[:, 0], fps, rotation_order, end_sites=sites)


def fit_error(motion: BVHMotion, positions, units: str = "m") -> float:
    """Largest joint distance (metres) between a BVH motion's forward kinematics and `positions`."""
    got = motion.global_positions() / UNITS[units]
    return float(np.linalg.norm(got - np.asarray(positions, np.float64), axis=-1).max())
