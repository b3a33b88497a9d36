"""Style cues: a few interpretable numbers per motion window that say what a style looks like.

A style shows in posture, amplitude, tempo and dynamics. Each cue below is one number per window of
joint positions (T, 22, 3), Y up, 20 fps, on any body: lengths are divided by the window's own leg
length L (right thigh + shin, median over frames) and speeds are per second, so a tall and a
short actor walking alike get the same cues. Every cue is unchanged by moving the whole motion
(X, Y or Z) or turning it about the vertical, because positions are read in the *body frame*:
origin on the floor under the pelvis, +Z the way the body faces (the smoothed normal of the hips
and shoulders, as in the HumanML3D root rotation but without pinning frame 0), +X to its left;
the floor is the lowest foot point of the window.

    posture    head_height     head above the floor, mean                          L
               trunk_pitch     pelvis→neck tilt forward (+) from vertical, mean   degrees
               head_ahead      head in front of the pelvis, mean                   L
               shoulder_height shoulders above the neck joint, mean (raised +)     L
    amplitude  arm_swing       forward-backward spread of the wrists (std)         L
               stride          forward range of the ankles (max − min)             L
               knee_lift       vertical range of the knees (max − min)             L
               hand_spread     sideways distance between the wrists, mean          L
    tempo      cadence         steps per second: the ankles passing each other     1/s
               speed           horizontal speed of the pelvis, mean                L/s
    dynamics   bounce          vertical spread of the pelvis (std)                 L
               sway            sideways spread of the pelvis path (std, detrended) L
               jerk            third derivative of the joint positions, mean norm  L/s³
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d

from ..data import retarget
from ..motion.features import check_positions

FPS = 20.0
PELVIS, NECK, HEAD = 0, 12, 15
SHOULDERS, WRISTS, KNEES, ANKLES = (16, 17), (20, 21), (4, 5), (7, 8)
FEET = (7, 8, 10, 11)
HIPS, LEGS = (1, 2), ((1, 4, 7), (2, 5, 8))  # left, right: hip → knee → ankle
FACING_SIGMA = 10  # frames: smooths the hips' and shoulders' twist out of the facing direction
STILL = 0.05  # L: ankle swing below this is standing, cadence 0

CUE_GROUPS = {
    "posture": ("head_height", "trunk_pitch", "head_ahead", "shoulder_height"),
    "amplitude": ("arm_swing", "stride", "knee_lift", "hand_spread"),
    "tempo": ("cadence", "speed"),
    "dynamics": ("bounce", "sway", "jerk"),
}
CUES = tuple(c for group in CUE_GROUPS.values() for c in group)
UNITS = {"head_height": "L", "trunk_pitch": "deg", "head_ahead": "L", "shoulder_height": "L",
         "arm_swing": "L", "stride": "L", "knee_lift": "L", "hand_spread": "L", "cadence": "1/s",
         "speed": "L/s", "bounce": "L", "sway": "L", "jerk": "L/s^3"}


def leg_length(positions) -> float:
    """The unit L: median right thigh + shin length (the one registration rescales by)."""
    L = retarget.leg_length(positions)
    if not L > 1e-9:
        raise ValueError("positions: the legs have zero length; is this a 22-joint HumanML3D skeleton?")
    return L


def facing_yaw(positions, sigma: float = FACING_SIGMA) -> np.ndarray:
    """(T,) heading angle φ of each frame: forward = (sin φ, 0, cos φ) = up × (right − left)."""
    p = np.asarray(positions, np.float64)
    across = (p[:, HIPS[1]] - p[:, HIPS[0]]) + (p[:, SHOULDERS[1]] - p[:, SHOULDERS[0]])  # toward the right
    forward = np.stack([across[:, 2], np.zeros(len(p)), -across[:, 0]], -1)  # up × across, (T, 3)
    if sigma > 0 and len(p) > 1:
        forward = gaussian_filter1d(forward, sigma, axis=0, mode="nearest")
    if (np.linalg.norm(forward[:, [0, 2]], axis=-1) < 1e-9).any():
        raise ValueError("positions: cannot tell which way the body faces (hips and shoulders coincide)")
    return np.arctan2(forward[:, 0], forward[:, 2])


def rotate_to_facing(vectors, yaw) -> np.ndarray:
    """Vectors (T, ..., 3) turned about Y by −yaw[t], so that each frame's forward becomes +Z."""
    v = np.asarray(vectors, np.float64)
    c, s = np.cos(yaw), np.sin(yaw)
    c, s = c.reshape((-1,) + (1,) * (v.ndim - 2)), s.reshape((-1,) + (1,) * (v.ndim - 2))
    out = v.copy()
    out[..., 0] = c * v[..., 0] - s * v[..., 2]
    out[..., 2] = s * v[..., 0] + c * v[..., 2]
    return out


def body_frame(positions, yaw=None) -> np.ndarray:
    """(T, 22, 3) positions relative to the floor point under the pelvis, facing +Z, in leg lengths."""
    p = check_positions(positions)
    yaw = facing_yaw(p) if yaw is None else yaw
    q = p.copy()
    q[..., [0, 2]] -= p[:, PELVIS:PELVIS + 1, [0, 2]]
    q[..., 1] -= p[:, FEET, 1].min()
    return rotate_to_facing(q, yaw) / leg_length(p)


def step_times(d, fps: float = FPS, band: float = 0.15) -> np.ndarray:
    """Times (s) at which a signal crosses its mid-range, with hysteresis of `band` × its range."""
    d = np.asarray(d, np.float64)
    e = d - (d.max() + d.min()) / 2
    h = band * (d.max() - d.min()) / 2
    state, last, times = 0, 0, []
    for t, x in enumerate(e):
        s = 1 if x > h else -1 if x < -h else 0
        if s == 0:
            continue
        if state and s != state:  # a zero crossing lies in [last, t]: the last sign change there
            j = max(k for k in range(last, t) if np.sign(e[k]) != np.sign(e[k + 1]) or e[k] == 0)
            frac = e[j] / (e[j] - e[j + 1]) if e[j] != e[j + 1] else 0.0
            times.append((j + frac) / fps)
        state, last = s, t
    return np.asarray(times)


def cues(positions, fps: float = FPS) -> dict:
    """The CUES of one window of joint positions (T, 22, 3), T ≥ 4; see the module docstring."""
    p = check_positions(positions, min_frames=4)
    L = leg_length(p)
    yaw = facing_yaw(p)
    q = body_frame(p, yaw)  # (T, 22, 3) in L, body frame
    spine = q[:, NECK] - q[:, PELVIS]
    out = {
        "head_height": q[:, HEAD, 1].mean(),
        "trunk_pitch": np.degrees(np.arctan2(spine[:, 2], spine[:, 1])).mean(),
        "head_ahead": (q[:, HEAD, 2] - q[:, PELVIS, 2]).mean(),
        "shoulder_height": (q[:, SHOULDERS, 1].mean(1) - q[:, NECK, 1]).mean(),
        "arm_swing": q[:, WRISTS, 2].std(0).mean(),
        "stride": np.ptp(q[:, ANKLES, 2], axis=0).mean(),
        "knee_lift": np.ptp(q[:, KNEES, 1], axis=0).mean(),
        "hand_spread": np.abs(q[:, WRISTS[0], 0] - q[:, WRISTS[1], 0]).mean(),
    }
    # tempo: steps are the ankles passing each other (their forward offset changes sign)
    gap = q[:, ANKLES[0], 2] - q[:, ANKLES[1], 2]
    times = step_times(gap, fps) if np.ptp(gap) > STILL else np.array([])
    out["cadence"] = (0.0 if np.ptp(gap) <= STILL else float("nan") if len(times) < 2
                      else (len(times) - 1) / (times[-1] - times[0]))
    step = rotate_to_facing(np.diff(p[:, PELVIS], axis=0), yaw[:-1]) / L  # (T−1, 3) pelvis steps, body frame
    out["speed"] = np.linalg.norm(step[:, [0, 2]], axis=-1).mean() * fps
    out["bounce"] = q[:, PELVIS, 1].std()
    lateral = np.concatenate([[0.0], np.cumsum(step[:, 0])])  # the pelvis path, sideways
    t = np.arange(len(lateral))
    out["sway"] = (lateral - np.polyval(np.polyfit(t, lateral, 1), t)).std()
    out["jerk"] = np.linalg.norm(np.diff(p, 3, axis=0), axis=-1).mean() * fps ** 3 / L
    return {k: float(out[k]) for k in CUES}


def cue_table(windows, fps: float = FPS) -> np.ndarray:
    """(N, len(CUES)) cues of a list of windows (NaN where a cue is undetermined, e.g. one step seen)."""
    return np.array([[c[k] for k in CUES] for c in map(lambda w: cues(w, fps), windows)]).reshape(-1, len(CUES))


TRACKS = {"head_height": "head above the floor (L)", "trunk_pitch": "trunk pitch, forward + (deg)",
          "arm_swing": "left wrist ahead of the right (L)"}


def cue_tracks(positions) -> dict:
    """Three posture and amplitude cues frame by frame, (T,) each (the window cues are their means or spreads):
    head height (L), trunk pitch (degrees, forward +), and the left wrist's lead over the right (L), whose
    swing from + to − is the arm swing."""
    p = check_positions(positions, min_frames=2)
    q = body_frame(p)
    spine = q[:, NECK] - q[:, PELVIS]
    return {"head_height": q[:, HEAD, 1],
            "trunk_pitch": np.degrees(np.arctan2(spine[:, 2], spine[:, 1])),
            "arm_swing": q[:, WRISTS[0], 2] - q[:, WRISTS[1], 2]}
