"""The last layer of a planned clip: per style × content joint-angle moments fitted to real capture.

The style parameters (styles.py) say how a style walks, runs or punches in a few dozen numbers:
lean, arm swing, tempo. A judge of real styles reads more than those: where each joint sits on
average, how widely it moves, and how fast that movement changes — the means and spreads over
time of joint positions, velocities and accelerations. This layer gives each (style, content)
cell the freedom to match those, joint by joint, on the planned joint angles a (T, 22, 3) in
degrees (pitch, yaw, roll), before the feet are locked:

    a'(t) = a̅ + g ⊙ (a(t) − a̅) + o + s ⊙ n(t)

- o, a posture offset (pitch only for the midline joints: pelvis, spine, neck, head);
- g = exp(log g), an amplitude gain of each angle about the clip's mean a̅;
- s ⊙ n(t), band-limited variation: n is a sum of four sines of random frequency in 0.5–2 Hz and
  random phase per angle, scaled to unit spread, so s is its spread in degrees. Real capture has
  this small continual motion (sway, settling, tremor); it raises the velocity and acceleration
  spreads without changing the mean pose.

Left and right joints share their numbers (mirrored: a right joint's yaw and roll offsets are the
left's negated), so 96 numbers describe a cell (N_PARAMS). Because the layer acts before the
foot lock, the physics guarantees of the generator hold: feet stay planted, bones keep their
lengths. `tools/fit_joint_moments.py` fits the numbers to the Xia train split and writes them to
`fitted_joint_moments.json` beside this file. A content without numbers of its own (too few real
windows, or not in Xia: waves, side steps…) takes its style's walking numbers; without the file
the layer does nothing.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .fitted import load_fitted

MOMENTS_FILE = Path(__file__).with_name("fitted_joint_moments.json")
MIDLINE = (0, 3, 6, 9, 12, 15)  # pelvis, spine1–3, neck, head
PAIRED = ((1, 2), (4, 5), (7, 8), (13, 14), (16, 17), (18, 19))  # (left, right): hips, knees, ankles, collars, shoulders, elbows
MIRROR = np.array([1.0, -1.0, -1.0])  # (pitch, yaw, roll) of a right joint = MIRROR · the left's
N_OFFSET = len(MIDLINE) + 3 * len(PAIRED)  # 24
N_GAIN = 3 * len(MIDLINE) + 3 * len(PAIRED)  # 36
N_PARAMS = N_OFFSET + 2 * N_GAIN  # 96 numbers per (style, content): offsets, log gains, spreads
BAND_HZ = (0.5, 2.0)  # frequencies of the variation: sway and settling, not tremor (jerk grows as f³)
N_SINES = 4
OFFSET_LIMIT, LOG_GAIN_LIMIT, SPREAD_LIMIT = 40.0, 1.0, 25.0  # degrees, log, degrees


def unpack(theta) -> tuple:
    """(96,) cell numbers → offset (22, 3) degrees, gain (22, 3), spread (22, 3) degrees."""
    theta = np.asarray(theta, np.float64)
    if theta.shape != (N_PARAMS,):
        raise ValueError(f"theta: expected {N_PARAMS} numbers, got shape {theta.shape}")
    offset, log_gain, spread = np.zeros((22, 3)), np.zeros((22, 3)), np.zeros((22, 3))
    k = 0
    for j in MIDLINE:
        offset[j, 0] = theta[k]
        k += 1
    for left, right in PAIRED:
        offset[left], offset[right] = theta[k:k + 3], theta[k:k + 3] * MIRROR
        k += 3
    for target in (log_gain, spread):
        for j in MIDLINE:
            target[j] = theta[k:k + 3]
            k += 3
        for left, right in PAIRED:
            target[left] = target[right] = theta[k:k + 3]
            k += 3
    return offset, np.exp(log_gain), np.abs(spread)


def clip_to_limits(theta) -> np.ndarray:
    """The numbers with offsets, log gains and spreads inside their limits."""
    t = np.asarray(theta, np.float64).copy()
    t[:N_OFFSET] = np.clip(t[:N_OFFSET], -OFFSET_LIMIT, OFFSET_LIMIT)
    t[N_OFFSET:N_OFFSET + N_GAIN] = np.clip(t[N_OFFSET:N_OFFSET + N_GAIN], -LOG_GAIN_LIMIT, LOG_GAIN_LIMIT)
    t[N_OFFSET + N_GAIN:] = np.clip(t[N_OFFSET + N_GAIN:], 0.0, SPREAD_LIMIT)
    return t


def variation(T: int, fps: float, rng) -> np.ndarray:
    """(T, 22, 3) band-limited unit-spread signal: N_SINES sines per angle, random frequency and phase."""
    t = np.arange(T)[:, None, None] / fps
    freq = rng.uniform(*BAND_HZ, size=(N_SINES, 22, 3))
    phase = rng.uniform(0.0, 2 * np.pi, size=(N_SINES, 22, 3))
    return np.sin(2 * np.pi * freq[:, None] * t + phase[:, None]).sum(0) / np.sqrt(N_SINES / 2)  # each sine: variance ½


def apply_moments(angles, theta, fps: float, rng, strength: float = 1.0) -> np.ndarray:
    """a' = a̅ + g^k ⊙ (a − a̅) + o + k·s ⊙ n(t) on (T, 22, 3) angles in degrees, k = `strength`
    (1: the fitted layer; 0: its posture offsets alone)."""
    a = np.asarray(angles, np.float64)
    offset, gain, spread = unpack(theta)
    mean = a.mean(0, keepdims=True)  # a̅, (1, 22, 3)
    return mean + gain ** strength * (a - mean) + offset + strength * spread * variation(len(a), fps, rng)


def fitted_moments(path: Path = MOMENTS_FILE) -> dict:
    """{(style, content): (96,) numbers} from the fitted file ({} without it)."""
    cells = load_fitted("cells", path)
    return {tuple(key.split(":")): np.asarray(v, np.float64) for key, v in cells.items()}


FITTED = fitted_moments()


def cell_moments(style: str, content: str, intensity: float = 1.0, table: dict | None = None):
    """The numbers a clip of this style and content gets (None when the layer does nothing).
    A content without numbers of its own takes the style's walking ones (as the style parameters
    do); like them, the result is neutral's + intensity · (the style's − neutral's)."""
    table = FITTED if table is None else table

    def numbers(s):
        return table.get((s, content), table.get((s, "walk")))
    neutral, mine = numbers("neutral"), numbers(style)
    if neutral is None and mine is None:
        return None
    neutral = np.zeros(N_PARAMS) if neutral is None else neutral
    mine = neutral if mine is None else mine
    return neutral + intensity * (mine - neutral)
