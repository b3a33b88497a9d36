"""The generator's body and its joint-angle vocabulary (the built-in data).

The body is the HumanML3D 22-joint tree with the reference bone lengths (left and right averaged),
but with a *natural* rest geometry instead of the template's axis-aligned directions: hips below
and beside the pelvis, feet pitched down so the ankle sits above the toe — the geometry real
HumanML3D motions have — and the trunk's bones (hips, spine, neck, head, collars, shoulders)
pointing as they do on the real Xia actor registered onto the template (fitted by
tools/fit_styles.py: their median directions in neutral walking, the trunk turned upright). With all local rotations at identity it stands
upright, arms hanging, facing +Z (left is +X). Bone lengths are what a per-clip body scales.

Joint angles are stored per frame and joint as (pitch, yaw, roll) in degrees and composed as
R = Rx(pitch) · Rz(roll) · Ry(yaw): the yaw (twist about the bone, for limbs and spine) first, then
the side roll, then the pitch. `Angles` has anatomical setters (hip flexion, knee flexion, ...)
that hide the sign conventions of each side.
"""
from __future__ import annotations

import numpy as np

from ..motion.skeleton import JOINT_NAMES, PARENTS, REFERENCE_BONE_LENGTHS, MIRROR, Skeleton
from .fitted import load_fitted

# natural rest directions (joint from parent), from the geometry of real HumanML3D poses
_DIRECTIONS = {
    1: (0.56, -0.82, -0.10), 2: (-0.56, -0.82, -0.10), 3: (0.0, 0.93, -0.37),
    4: (0.0, -1.0, 0.0), 5: (0.0, -1.0, 0.0), 6: (0.0, 0.98, 0.19),
    7: (0.0, -1.0, 0.0), 8: (0.0, -1.0, 0.0), 9: (0.0, 1.0, 0.06),
    10: (0.0, -0.39, 0.92), 11: (0.0, -0.39, 0.92), 12: (0.0, 0.996, -0.08),
    13: (0.55, 0.83, -0.09), 14: (-0.55, 0.83, -0.09), 15: (0.0, 0.69, 0.72),
    16: (0.985, -0.07, -0.115), 17: (-0.985, -0.07, -0.115), 18: (0.0, -1.0, 0.0),
    19: (0.0, -1.0, 0.0), 20: (0.0, -1.0, 0.0), 21: (0.0, -1.0, 0.0),
}
# the trunk's bones as the real actor's registered skeleton has them (fitted_styles.json, "body")
FITTED_DIRECTIONS = {int(j): tuple(d) for j, d in load_fitted("body").get("directions", {}).items()}
REST_DIRECTIONS = np.zeros((22, 3))
for _j, _d in {**_DIRECTIONS, **FITTED_DIRECTIONS}.items():
    REST_DIRECTIONS[_j] = np.asarray(_d) / np.linalg.norm(_d)
_full = np.concatenate([[0.0], REFERENCE_BONE_LENGTHS])
SYMMETRIC_LENGTHS = 0.5 * (_full + _full[list(MIRROR)])  # left and right averaged, joints 0..21
# bone groups whose lengths vary together in a per-clip body
_GROUPS = {"legs": (4, 5, 7, 8), "feet": (10, 11), "hips": (1, 2), "spine": (3, 6, 9),
           "neck": (12, 15), "collars": (13, 14, 16, 17), "arms": (18, 19, 20, 21)}

LEFT, RIGHT = 0, 1
LEG = {LEFT: (1, 4, 7, 10), RIGHT: (2, 5, 8, 11)}      # hip, knee, ankle, toe
ARM = {LEFT: (13, 16, 18, 20), RIGHT: (14, 17, 19, 21)}  # collar, shoulder, elbow, wrist
FOOT_CONTACT_JOINTS = (7, 10, 8, 11)  # the order of HumanML3D's contact block


def body_skeleton(scale: float = 1.0, group_factors: dict | None = None) -> Skeleton:
    """The generator body: natural rest directions, symmetric reference lengths × scale × group factors."""
    if not 0.5 < scale < 2.0:
        raise ValueError(f"scale: must be in (0.5, 2), got {scale}")
    lengths = SYMMETRIC_LENGTHS * scale
    for name, f in (group_factors or {}).items():
        if name not in _GROUPS:
            raise ValueError(f"group_factors: unknown group {name!r}; groups are {list(_GROUPS)}")
        lengths[list(_GROUPS[name])] *= f
    return Skeleton(JOINT_NAMES, PARENTS, REST_DIRECTIONS * lengths[:, None])


def random_body(rng: np.random.Generator, scale_range=(0.95, 1.05), jitter: float = 0.015) -> Skeleton:
    """A per-clip body: overall scale in `scale_range`, each bone group ±`jitter` (relative sd)."""
    factors = {g: float(np.clip(1 + jitter * rng.standard_normal(), 1 - 3 * jitter, 1 + 3 * jitter))
               for g in _GROUPS}
    return body_skeleton(float(rng.uniform(*scale_range)), factors)


def leg_length(skeleton: Skeleton) -> float:
    """Hip-to-ankle length of the straight leg (thigh + shank), metres."""
    lengths = skeleton.bone_lengths()
    return float(lengths[4] + lengths[7])


# ---------------------------------------------------------------- rotations
def _axis_mats(angle_rad, axis: int) -> np.ndarray:
    """Rotation matrices about one coordinate axis, (..., 3, 3)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    m = np.zeros(np.shape(angle_rad) + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[..., axis, axis] = 1.0
    m[..., i, i], m[..., i, j], m[..., j, i], m[..., j, j] = c, -s, s, c
    return m


def rot_x(a):
    """Rotation about X by a (radians), (..., 3, 3)."""
    return _axis_mats(np.asarray(a, float), 0)


def rot_y(a):
    """Rotation about Y by a (radians), (..., 3, 3); positive turns +Z toward +X (to the left)."""
    return _axis_mats(np.asarray(a, float), 1)


def rot_z(a):
    """Rotation about Z by a (radians), (..., 3, 3)."""
    return _axis_mats(np.asarray(a, float), 2)


def euler_pyr(angles_deg) -> np.ndarray:
    """(..., 3) (pitch, yaw, roll) in degrees → Rx(pitch) · Rz(roll) · Ry(yaw), (..., 3, 3)."""
    a = np.deg2rad(np.asarray(angles_deg, float))
    return rot_x(a[..., 0]) @ rot_z(a[..., 2]) @ rot_y(a[..., 1])


class Angles:
    """Joint angles of T frames, (T, 22, 3) = (pitch, yaw, roll) in degrees, with anatomical setters."""

    def __init__(self, n_frames: int):
        self.a = np.zeros((int(n_frames), 22, 3))

    @property
    def n_frames(self) -> int:
        return self.a.shape[0]

    def add(self, joint: int, pitch=0.0, yaw=0.0, roll=0.0):
        """Add raw angles (degrees; scalars or (T,) arrays) to one joint."""
        self.a[:, joint, 0] += pitch
        self.a[:, joint, 1] += yaw
        self.a[:, joint, 2] += roll
        return self

    def pelvis(self, tilt=0.0, obliquity=0.0, turn=0.0):
        """Anterior tilt (+ forward), obliquity (+ left side up), turn (+ toward the left)."""
        return self.add(0, pitch=tilt, yaw=turn, roll=obliquity)

    def spine(self, lean=0.0, bend=0.0, turn=0.0, weights=(0.3, 0.35, 0.35)):
        """Trunk pitch forward, side bend (+ to the left), twist (+ to the left) over spine1..3."""
        for j, w in zip((3, 6, 9), weights):
            self.add(j, pitch=w * lean, yaw=w * turn, roll=-w * bend)
        return self

    def neck(self, pitch=0.0, tilt=0.0, turn=0.0):
        """Head pitch (+ down), tilt (+ toward the left shoulder), turn (+ to the left)."""
        return self.add(12, pitch=pitch, yaw=turn, roll=-tilt)

    def hip(self, side: int, flex=0.0, abduct=0.0, out=0.0):
        """Thigh flexion (+ forward), abduction (+ away from the midline), external rotation."""
        s = 1.0 if side == LEFT else -1.0
        return self.add(LEG[side][0], pitch=-flex, yaw=s * out, roll=s * abduct)

    def knee(self, side: int, flex=0.0):
        """Knee flexion (+ bends the shank backward)."""
        return self.add(LEG[side][1], pitch=flex)

    def ankle(self, side: int, plantar=0.0):
        """Ankle plantarflexion (+ toe down)."""
        return self.add(LEG[side][2], pitch=plantar)

    def collar(self, side: int, raise_=0.0, back=0.0):
        """Shoulder girdle elevation (+ up) and retraction (+ back)."""
        s = 1.0 if side == LEFT else -1.0
        return self.add(ARM[side][0], yaw=s * back, roll=s * raise_)

    def shoulder(self, side: int, flex=0.0, abduct=0.0, twist=0.0):
        """Upper-arm flexion (+ forward), abduction (+ out), external rotation (+)."""
        s = 1.0 if side == LEFT else -1.0
        return self.add(ARM[side][1], pitch=-flex, yaw=s * twist, roll=s * abduct)

    def elbow(self, side: int, flex=0.0):
        """Elbow flexion (+ forearm forward and up)."""
        return self.add(ARM[side][2], pitch=-flex)

    def wrist(self, side: int, flex=0.0):
        """Wrist flexion (moves only the extra hand joints of the mocap skeleton)."""
        return self.add(ARM[side][3], pitch=-flex)

    def matrices(self, heading=None) -> np.ndarray:
        """Local rotations (T, 22, 3, 3); the root is turned by `heading` (radians, (T,)) about Y."""
        R = euler_pyr(self.a)
        if heading is not None:
            R[:, 0] = rot_y(heading) @ R[:, 0]
        return R


# ---------------------------------------------------------------- time curves
def bump(u, mu, sigma):
    """A smooth periodic bump on the unit circle of phases: ≈ Gaussian(u − mu, sigma), peak 1."""
    k = 1.0 / (2 * np.pi * sigma) ** 2
    return np.exp(k * (np.cos(2 * np.pi * (np.asarray(u) - mu)) - 1.0))


def smoothstep(x):
    """3x² − 2x³ on [0, 1], clamped outside."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def keyframes(t, keys):
    """Piecewise smoothstep interpolation through (time, value) keys (sorted by time), held at the ends."""
    t = np.asarray(t, float)
    times = np.array([k[0] for k in keys], float)
    values = np.array([k[1] for k in keys], float)
    if np.any(np.diff(times) < 0):
        raise ValueError("keys: times must be sorted")
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 1)
    j = np.minimum(i + 1, len(times) - 1)
    span = np.maximum(times[j] - times[i], 1e-9)
    w = smoothstep((t - times[i]) / span)
    return values[i] + (values[j] - values[i]) * np.where(j > i, w, 0.0)


def shaped(c, jerk: float):
    """Make an oscillation c ∈ [−1, 1] squarer (more abrupt) as jerk goes from 0 to 1."""
    return np.sign(c) * np.abs(c) ** (1.0 / (1.0 + 2.0 * jerk))


def tremor(rng: np.random.Generator, t, amplitude: float, n: int = 3):
    """Band-limited tremor (5–8 Hz sum of sines with random phases), amplitude in degrees."""
    out = np.zeros_like(np.asarray(t, float))
    if amplitude <= 0:
        return out
    for _ in range(n):
        out += np.sin(2 * np.pi * rng.uniform(5.0, 8.0) * t + rng.uniform(0, 2 * np.pi))
    return amplitude * out / np.sqrt(n)


def slow_noise(rng: np.random.Generator, t, amplitude: float, period: float = 2.0, n: int = 3):
    """Slow smooth wandering (e.g. gaze, weight shift): sum of sines near 1/period Hz."""
    out = np.zeros_like(np.asarray(t, float))
    for _ in range(n):
        out += np.sin(2 * np.pi * rng.uniform(0.5, 1.5) / period * t + rng.uniform(0, 2 * np.pi))
    return amplitude * out / np.sqrt(n)
