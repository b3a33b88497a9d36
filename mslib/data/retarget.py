"""Cross-dataset registration (A §3.1, §4.1): any BVH → the HumanML3D body, 20 fps, canonical frame.

The steps, in the order HumanML3D preprocesses:
  1. resample the source to 20 fps (local rotations by slerp, translations linearly);
  2. forward kinematics on the source skeleton; up axis → +Y, handedness → right-handed;
  3. pick the 22 template joints through a joint map (joint_maps.py);
  4. rescale to the reference body: keep every bone's direction, give it the template's length,
     scale the root path by the leg-length ratio (HumanML3D's IK on the source + FK with the
     template offsets amounts to exactly this);
  5. floor to y = 0, frame-0 root XZ to the origin, initial facing to +Z; optionally mirror;
  6. the 263-d vector; 32-frame windows with 8-frame overlap for style clips.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..motion import features as F
from ..motion import rotations as rot
from ..motion.bvh import BVHMotion, read_bvh
from ..motion.skeleton import HUMANML3D, KINEMATIC_CHAINS, mirror_positions
from .joint_maps import resolve_joint_map

TARGET_FPS = 20
WINDOW, WINDOW_OVERLAP = 32, 8  # A §4.1


@dataclass
class Registered:
    """A motion on the template body: positions (T, 22, 3), features (T−1, 263) and what was done."""

    positions: np.ndarray = field(repr=False)
    features: np.ndarray = field(repr=False)
    fps: float
    joint_map: dict = field(repr=False)
    info: dict


# ---------------------------------------------------------------- 1. time
def resample(motion: BVHMotion, fps: float = TARGET_FPS) -> BVHMotion:
    """The motion at another frame rate: slerp for local rotations, lerp for translations."""
    if fps <= 0:
        raise ValueError(f"fps: must be > 0, got {fps}")
    T = motion.n_frames
    if abs(motion.fps - fps) < 1e-9 or T < 2:
        return motion
    t = np.arange(0, (T - 1) / motion.fps + 1e-9, 1.0 / fps) * motion.fps  # source frame index, float
    i0 = np.minimum(np.floor(t).astype(int), T - 1)
    i1 = np.minimum(i0 + 1, T - 1)
    w = (t - i0)[:, None]
    q = rot.quat_fix(rot.matrix_to_quat(motion.local_rotations))  # (T, J, 4), continuous in time
    q_new = rot.quat_slerp(q[i0], q[i1], np.broadcast_to(w, q[i0].shape[:-1]))
    pos = motion.positions[i0] * (1 - w[..., None]) + motion.positions[i1] * w[..., None]
    return BVHMotion(motion.skeleton, motion.channels, motion.rotation_orders,
                     rot.quat_to_matrix(q_new), pos, fps, motion.end_sites)


# ---------------------------------------------------------------- 2. axes
def to_y_up(positions, up: str = "y", handedness: str = "right") -> np.ndarray:
    """Positions (..., 3) with +Y up in a right-handed frame (up ∈ x, y, z, −x, …)."""
    p = np.asarray(positions, dtype=np.float64)
    up = up.lower()
    if up not in ("x", "y", "z", "-x", "-y", "-z"):
        raise ValueError(f"up: expected one of x, y, z, -x, -y, -z, got {up!r}")
    if handedness not in ("right", "left"):
        raise ValueError(f"handedness: expected 'right' or 'left', got {handedness!r}")
    if handedness == "left":
        p = p * np.array([1.0, 1.0, -1.0])  # flip one axis to change chirality
    axis = "xyz".index(up[-1])
    if axis != 1 or up.startswith("-"):
        target = np.zeros(3)
        target[axis] = -1.0 if up.startswith("-") else 1.0
        q = rot.quat_between(target, np.array([0.0, 1.0, 0.0]))
        p = rot.quat_rotate(np.broadcast_to(q, p.shape[:-1] + (4,)), p)
    return p


def guess_up_axis(template_positions) -> str:
    """The axis pointing from the ankles to the head over the take ('y', 'z', '-y', …), median frame.

    Feet to head, not pelvis to head: a stooped or crouching body keeps its head above its feet.
    """
    p = np.asarray(template_positions)
    spine = np.median(p[:, 15] - 0.5 * (p[:, 7] + p[:, 8]), axis=0)
    axis = int(np.argmax(np.abs(spine)))
    return ("-" if spine[axis] < 0 else "") + "xyz"[axis]


# ---------------------------------------------------------------- 3–4. template body
def select_template_joints(global_positions, skeleton, joint_map) -> np.ndarray:
    """(T, J_src, 3) source joints → (T, 22, 3) template joints through a joint map."""
    idx = {n: i for i, n in enumerate(skeleton.names)}
    out = []
    for entry in joint_map.values():
        if isinstance(entry, str):
            out.append(global_positions[:, idx[entry]])
        else:
            _, a, b, t = entry
            pa, pb = global_positions[:, idx[a]], global_positions[:, idx[b]]
            out.append(pa + t * (pb - pa))
    return np.stack(out, 1)


def leg_length(positions) -> float:
    """Median right thigh + shin length over frames (HumanML3D scales the root path by its ratio)."""
    p = np.asarray(positions)
    return float(np.median(np.linalg.norm(p[:, 5] - p[:, 2], axis=-1) + np.linalg.norm(p[:, 8] - p[:, 5], axis=-1)))


def rescale_to_reference(positions, skeleton=HUMANML3D) -> np.ndarray:
    """Template positions of any body → the reference body: bone directions kept, lengths replaced."""
    p = np.asarray(positions, dtype=np.float64)
    src_leg = leg_length(p)
    if not src_leg > 1e-9:
        raise ValueError("positions: the legs have zero length; check the joint map")
    lengths = skeleton.bone_lengths()
    out = np.empty_like(p)
    out[:, 0] = p[:, 0] * (leg_length(skeleton.rest_positions()[None]) / src_leg)
    for chain in KINEMATIC_CHAINS:
        for a, b in zip(chain[:-1], chain[1:]):
            bone = p[:, b] - p[:, a]
            norm = np.linalg.norm(bone, axis=-1, keepdims=True)
            rest_dir = skeleton.offsets[b] / lengths[b]
            direction = np.where(norm > 1e-9, bone / np.maximum(norm, 1e-12), rest_dir)
            out[:, b] = out[:, a] + lengths[b] * direction
    return out


# ---------------------------------------------------------------- 5. canonical frame
def facing_direction(frame) -> np.ndarray:
    """Unit forward (XZ) of one pose: cross(up, across), across = right − left hips and shoulders."""
    across = (frame[2] - frame[1]) + (frame[17] - frame[16])
    forward = np.cross([0.0, 1.0, 0.0], across)
    forward[1] = 0
    n = np.linalg.norm(forward)
    if n < 1e-9:
        raise ValueError("positions: cannot tell which way the body faces (hips and shoulders coincide)")
    return forward / n


def canonicalize(positions, floor: bool = True) -> np.ndarray:
    """Floor at y = 0 (min over the clip), frame-0 root XZ at the origin, initial facing +Z."""
    p = np.array(positions, dtype=np.float64)
    if floor:
        p[..., 1] -= p[..., 1].min()
    p[..., [0, 2]] -= p[0, 0, [0, 2]]
    q = rot.quat_between(facing_direction(p[0]), np.array([0.0, 0.0, 1.0]))
    return rot.quat_rotate(np.broadcast_to(q, p.shape[:-1] + (4,)), p)


def window_starts(n_frames: int, length: int = WINDOW, overlap: int = WINDOW_OVERLAP) -> list:
    """Start frames of `length`-frame windows overlapping by `overlap` (the tail that doesn't fit is dropped)."""
    if length <= overlap or overlap < 0:
        raise ValueError(f"window: length {length} must exceed overlap {overlap} ≥ 0")
    return list(range(0, n_frames - length + 1, length - overlap))


def cut_windows(positions, length: int = WINDOW, overlap: int = WINDOW_OVERLAP) -> list:
    """Windows of a registered motion, each re-centred and re-faced (the take's floor is kept)."""
    return [canonicalize(positions[s:s + length], floor=False)
            for s in window_starts(len(positions), length, overlap)]


# ---------------------------------------------------------------- the pipeline
def register_motion(motion: BVHMotion, dialect="auto", fps: float = TARGET_FPS, up: str = "auto",
                    handedness: str = "right", mirror: bool = False, source: str = "motion") -> Registered:
    """A parsed BVH motion → positions and features on the template body (steps 1–6 above)."""
    jmap = resolve_joint_map(motion.skeleton, dialect, source)
    src_fps = motion.fps
    motion = resample(motion, fps)
    if motion.n_frames < 2:
        raise ValueError(f"{source}: {motion.n_frames} frame(s) at {fps} fps; need at least 2")
    picked = select_template_joints(motion.global_positions(), motion.skeleton, jmap)
    up_axis = guess_up_axis(picked) if up == "auto" else up
    picked = to_y_up(picked, up_axis, handedness)
    positions = canonicalize(rescale_to_reference(picked))
    if mirror:
        positions = canonicalize(mirror_positions(positions))
    info = {"source": source, "source_fps": src_fps, "fps": fps, "frames": int(len(positions)),
            "up": up_axis, "handedness": handedness, "mirrored": bool(mirror),
            "scale": float(leg_length(HUMANML3D.rest_positions()[None]) / leg_length(picked))}
    return Registered(positions.astype(np.float32), F.encode(positions), fps, jmap, info)


def register_bvh(path, dialect="auto", fps: float = TARGET_FPS, up: str = "auto",
                 handedness: str = "right", mirror: bool = False) -> Registered:
    """Read a BVH file and register it onto the template body (see `register_motion`)."""
    return register_motion(read_bvh(path), dialect, fps, up, handedness, mirror, source=str(Path(path)))
