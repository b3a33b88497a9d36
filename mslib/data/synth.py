"""The built-in stylized mocap generator: one clip from (content, style, seed, index).

Pipeline of `generate_clip`:
    style + content parameters → joint-angle plan driven by a gait/action phase (gait.py, actions.py)
    → the style × content per-joint layer fitted to real capture (joint_moments.py) → local rotations → forward kinematics on a per-clip body (the HumanML3D 22-joint tree)
    → root translation derived from the stance foot (footlock.anchor_root)
    → feet locked on the floor by leg IK (footlock.lock_feet) → joint positions (T, 22, 3).
A clip is a pure function of (seed, index, content, style, ...): its random generator is
`np.random.default_rng([seed, index])`, so any subset regenerates identically, in any order or
process. `plausibility` measures what tests check: foot slide in contact, floor contact, bone
lengths, joint speeds. The fitted layer can amplify a plan past what a body does; a clip that comes
out with a joint faster than MAX_JOINT_SPEED, or an in-place content whose root wanders
IN_PLACE_TRAVEL or more, is made again with the layer's gains and variation weakened
(LAYER_FALLBACK), so every clip keeps these limits by construction.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.ndimage import gaussian_filter1d

from ..motion import rotations as rot
from ..motion.skeleton import PARENTS, Skeleton, forward_kinematics, positions_bone_lengths
from . import actions, gait, joint_moments, kin, styles
from .body import FOOT_CONTACT_JOINTS, leg_length, random_body, rot_y
from .footlock import anchor_root, lock_feet

GENERATOR_VERSION = 9  # bump on any change to the generated numbers: cached corpora are rebuilt
DURATION_RANGE = (2.0, 10.0)  # seconds
ANGLE_SMOOTHING = 0.04  # s: Gaussian σ over time of the planned joint angles (real capture is smoother)
MAX_JOINT_SPEED = 12.0  # m/s: no joint of a clip moves faster (a fast kick's foot is about 10)
IN_PLACE_CONTENTS, IN_PLACE_TRAVEL = ("stand", "punch", "wave"), 0.25  # m: root range (x or z) of in-place contents
LAYER_FALLBACK = (0.5, 0.25, 0.0)  # strengths of the layer's gains and variation, tried in turn past a limit
_PLANNERS = {"gait": gait.locomotion, "stand": actions.stand, "punch": actions.punch,
             "kick": actions.kick, "wave": actions.wave, "jump": actions.jump}


@dataclass
class SynthClip:
    """A generated clip: positions (T, 22, 3) m, local rotations, root, body, contacts (T, 4)."""

    positions: np.ndarray
    rotations: np.ndarray
    root: np.ndarray
    skeleton: Skeleton
    contacts: np.ndarray  # joints 7, 10, 8, 11 (left ankle, left toe, right ankle, right toe)
    fps: float
    meta: dict = field(default_factory=dict)
    foot_contacts: np.ndarray | None = None  # (T, 2) left, right foot down (any part)
    foot_pitch: np.ndarray | None = None  # (T, 2) degrees in contact: − on the heel, + on the toe

    @property
    def n_frames(self) -> int:
        return self.positions.shape[0]

    def turned(self, yaw: float, shift) -> "SynthClip":
        """The same clip rotated by yaw (radians) about +Y, then translated by shift (3,)."""
        Ry = rot_y(yaw)
        R = self.rotations.copy()
        R[:, 0] = Ry @ R[:, 0]
        root = self.root @ Ry.T + np.asarray(shift, float)
        pos = self.positions @ Ry.T + np.asarray(shift, float)
        return replace(self, positions=pos, rotations=R, root=root)


def facing_yaw(positions) -> float:
    """Yaw (radians, about +Y from +Z) of the initial facing: across = (p2 − p1) + (p17 − p16)."""
    p = np.asarray(positions)[0]
    across = (p[2] - p[1]) + (p[17] - p[16])
    forward = np.cross([0.0, 1.0, 0.0], across)
    return float(np.arctan2(forward[0], forward[2]))


def canonicalize(clip: SynthClip) -> SynthClip:
    """HumanML3D placement: frame-0 root over the origin, initial facing +Z (floor stays y = 0)."""
    yaw = facing_yaw(clip.positions)
    start = rot_y(-yaw) @ clip.root[0]
    return clip.turned(-yaw, -np.array([start[0], 0.0, start[2]]))


def _slerp_clip(clip: SynthClip, fps: float):
    """Rotations slerped and root, contacts, pitch interpolated at another frame rate."""
    T = clip.n_frames
    n = int(np.floor((T - 1) * fps / clip.fps + 1e-9)) + 1
    x = np.arange(n) * clip.fps / fps
    i0 = np.minimum(np.floor(x + 1e-9).astype(int), T - 1)
    i1 = np.minimum(i0 + 1, T - 1)
    w = np.clip(x - i0, 0.0, 1.0)
    q = rot.matrix_to_quat(clip.rotations)
    R = rot.quat_to_matrix(rot.quat_slerp(q[i0], q[i1], np.broadcast_to(w[:, None], q[i0].shape[:-1])))
    root = clip.root[i0] * (1 - w[:, None]) + clip.root[i1] * w[:, None]
    exact = (w < 1e-9)[:, None]
    contacts = clip.contacts[i0] & (clip.contacts[i1] | exact)
    feet = pitch = None
    if clip.foot_contacts is not None:
        feet = clip.foot_contacts[i0] & (clip.foot_contacts[i1] | exact)
        pitch = clip.foot_pitch[i0] * (1 - w[:, None]) + clip.foot_pitch[i1] * w[:, None]
    return R, root, contacts, feet, pitch


def resample_clips(clips, fps: float, relock: bool = True) -> list:
    """Clips at another frame rate: rotations slerped, root interpolated, forward kinematics; then
    (relock) the feet locked again at the new rate, so contacts stay exact. Batched over clips."""
    if not fps > 0:
        raise ValueError(f"fps: must be > 0, got {fps}")
    parts = [_slerp_clip(c, fps) for c in clips]
    out = []
    if relock and parts and all(p[3] is not None for p in parts):
        lengths = [len(p[0]) for p in parts]
        stops = np.cumsum(lengths)
        segments = list(zip(stops - lengths, stops))
        offsets = np.concatenate([np.repeat(c.skeleton.offsets[:, :, None], n, axis=2)
                                  for c, n in zip(clips, lengths)], axis=2)
        Rs = kin.to_soa(np.concatenate([p[0] for p in parts]))
        root = np.concatenate([p[1] for p in parts])
        feet = np.concatenate([p[3] for p in parts])
        pitch = np.concatenate([p[4] for p in parts])
        rel, G = kin.fk(PARENTS, offsets, Rs, np.zeros((len(root), 3)), return_globals=True)
        Rs, root, c4, pitch = lock_feet(offsets, Rs, root, rel, G, feet, pitch, fps, segments)
        pos = kin.fk(PARENTS, offsets, Rs, root)
        R = kin.from_soa(Rs)
        for c, (a, b) in zip(clips, segments):
            out.append(SynthClip(pos[a:b], R[a:b], root[a:b], c.skeleton, c4[a:b], fps,
                                 dict(c.meta, fps=fps, n_frames=int(b - a)), feet[a:b], pitch[a:b]))
        return out
    for c, (R, root, contacts, feet, pitch) in zip(clips, parts):
        pos = forward_kinematics(c.skeleton, R, root)
        out.append(SynthClip(pos, R, root, c.skeleton, contacts, fps, dict(c.meta, fps=fps, n_frames=len(R)),
                             feet, pitch))
    return out


def resample(clip: SynthClip, fps: float, relock: bool = True) -> SynthClip:
    """One clip at another frame rate (see `resample_clips`)."""
    return resample_clips([clip], fps, relock)[0]


def travel_stats(positions, fps: float) -> dict:
    """Mean root speed (m/s) on the ground, and the travel direction relative to the initial facing."""
    root = np.asarray(positions)[:, 0, [0, 2]]
    T = len(root)
    path = np.linalg.norm(np.diff(root, axis=0), axis=-1).sum()
    disp = root[-1] - root[0]
    direction = np.degrees(np.arctan2(disp[0], disp[1]) - facing_yaw(positions))
    direction = (direction + 180.0) % 360.0 - 180.0
    return {"speed": float(path / max(T - 1, 1) * fps),
            "net_speed": float(np.linalg.norm(disp) / max(T - 1, 1) * fps),
            "travel_direction": float(direction)}


def _prepare(spec: dict, layer_strength: float = 1.0):
    """Everything of one clip before the batched kinematics: parameters, body, joint-angle plan
    (the fitted layer's gains and variation at `layer_strength`, its posture offsets in full)."""
    content, style = spec.get("content"), spec.get("style", "neutral")
    substyle, fps = spec.get("substyle"), float(spec.get("fps", 20.0))
    seed, index = int(spec.get("seed", 0)), int(spec.get("index", 0))
    intensity, duration = float(spec.get("intensity", 1.0)), spec.get("duration")
    if content not in styles.CONTENTS:
        raise ValueError(f"content: must be one of {list(styles.CONTENTS)}, got {content!r}")
    if style not in styles.STYLES:
        raise ValueError(f"style: must be one of {list(styles.STYLES)}, got {style!r}")
    if substyle is not None and substyle not in styles.SUBSTYLES[style]:
        raise ValueError(f"substyle: must be one of {list(styles.SUBSTYLES[style])} for style "
                         f"{style!r}, got {substyle!r}")
    if not 5.0 <= fps <= 240.0:
        raise ValueError(f"fps: must be in [5, 240], got {fps}")
    if seed < 0 or index < 0:
        raise ValueError(f"seed and index: must be non-negative, got {seed}, {index}")
    rng = np.random.default_rng([seed, index])
    pick = int(rng.integers(len(styles.SUBSTYLES[style])))
    substyle = styles.SUBSTYLES[style][pick] if substyle is None else substyle
    drawn = float(rng.uniform(*DURATION_RANGE))
    duration = drawn if duration is None else float(duration)
    if not 0.5 <= duration <= 60.0:
        raise ValueError(f"duration: must be in [0.5, 60] seconds, got {duration}")
    sp = styles.sample_style(rng, style, substyle, intensity, content=content)
    cp = styles.sample_content(rng, content)
    sp.update(spec.get("style_params") or {})
    cp.update(spec.get("content_params") or {})
    body = random_body(rng)
    start = np.array([rng.uniform(-2, 2), 0.0, rng.uniform(-2, 2)])
    T = int(round(duration * fps)) + 1
    plan_rng = np.random.default_rng([seed, index, 1])
    plan = _PLANNERS[styles.CONTENT_TABLE[content][0]](T, fps, plan_rng, sp, cp, leg_length(body))
    if ANGLE_SMOOTHING > 0:
        plan.angles.a = gaussian_filter1d(plan.angles.a, ANGLE_SMOOTHING * fps, axis=0, mode="nearest")
    moments = joint_moments.cell_moments(style, content, intensity)
    if moments is not None:  # the fitted per-joint layer, before the feet are locked
        plan.angles.a = joint_moments.apply_moments(plan.angles.a, moments, fps, np.random.default_rng([seed, index, 2]),
                                                    strength=layer_strength)
    meta = {"content": content, "style": style, "substyle": substyle, "intensity": intensity,
            "seed": seed, "index": index, "fps": fps, "duration": float((T - 1) / fps), "n_frames": T}
    return dict(meta=meta, sp=sp, cp=cp, body=body, plan=plan, start=start,
                canonical=bool(spec.get("canonical", True)))


def _finish(prep, R, root, contacts4, positions, feet, pitch) -> SynthClip:
    """Wrap one clip's arrays with its metadata (captions from the measured speed)."""
    body, cp, plan = prep["body"], prep["cp"], prep["plan"]
    shift = prep["start"] - root[0] * np.array([1.0, 0.0, 1.0])
    clip = SynthClip(positions + shift, R, root + shift, body, contacts4, prep["meta"]["fps"],
                     foot_contacts=feet, foot_pitch=pitch)
    stats = travel_stats(clip.positions, clip.fps)
    clip.meta = dict(prep["meta"])
    clip.meta.update({
        "heading": float(np.degrees(facing_yaw(clip.positions))),
        "curvature": float(cp.get("curvature", 0.0)), "speed": stats["speed"],
        "travel_direction": stats["travel_direction"], "side": cp.get("side"),
        "caption": styles.caption(cp, None, stats["speed"]),
        "style_caption": styles.caption(cp, clip.meta["style"], stats["speed"], name_neutral=True),
        "params": prep["sp"],
        "content_params": {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in cp.items()},
        "plan": {k: float(v) for k, v in plan.info.items() if np.ndim(v) == 0},
    })
    return canonicalize(clip) if prep["canonical"] else clip


def within_limits(clip: SynthClip) -> bool:
    """No joint faster than MAX_JOINT_SPEED; an in-place content's root within IN_PLACE_TRAVEL."""
    speed = np.linalg.norm(np.diff(clip.positions, axis=0), axis=-1).max(initial=0.0) * clip.fps
    if speed > MAX_JOINT_SPEED:
        return False
    return (clip.meta["content"] not in IN_PLACE_CONTENTS
            or np.ptp(clip.positions[:, 0, [0, 2]], axis=0).max() < IN_PLACE_TRAVEL)


def generate_clips(specs) -> list:
    """Generate many clips at once (the kinematics run batched); each spec is a dict of
    generate_clip's arguments. The result of a clip does not depend on the others: one past
    the limits (`within_limits`) is made again with the fitted layer weakened (LAYER_FALLBACK)."""
    specs = [dict(s) for s in specs]
    out = _generate([_prepare(s) for s in specs])
    for strength in LAYER_FALLBACK:
        again = [i for i, clip in enumerate(out) if not within_limits(clip)]
        if not again:
            break
        redone = _generate([_prepare(specs[i], strength) for i in again])
        for i, clip in zip(again, redone):
            out[i] = clip
    return out


def _generate(preps) -> list:
    """The batched kinematics of prepared clips."""
    out = [None] * len(preps)
    for fps in sorted({p["meta"]["fps"] for p in preps}):
        group = [i for i, p in enumerate(preps) if p["meta"]["fps"] == fps]
        lengths = [preps[i]["meta"]["n_frames"] for i in group]
        stops = np.cumsum(lengths)
        segments = list(zip(stops - lengths, stops))
        cat = lambda f: np.concatenate([f(preps[i]) for i in group], 0)
        angles = cat(lambda p: p["plan"].angles.a)
        heading = cat(lambda p: p["plan"].heading)
        contacts = cat(lambda p: p["plan"].contacts)
        pitch = cat(lambda p: p["plan"].foot_pitch)
        offsets = np.concatenate([np.repeat(preps[i]["body"].offsets[:, :, None], n, axis=2)
                                  for i, n in zip(group, lengths)], axis=2)  # (J, 3, N)
        extra = cat(lambda p: p["plan"].root_offset if p["plan"].root_offset is not None
                    else np.zeros((p["meta"]["n_frames"], 3)))
        designed = cat(lambda p: p["plan"].root_height if p["plan"].root_height is not None
                       else np.full(p["meta"]["n_frames"], np.nan))
        R = kin.euler_pyr(angles)
        R[0] = kin.mm(kin.rot_y(heading), R[0])
        root, rel, G = anchor_root(PARENTS, offsets, R, contacts, pitch, fps, segments)
        stand = (-offsets[1, 1] + np.linalg.norm(offsets[4], axis=0) + np.linalg.norm(offsets[7], axis=0)
                 - offsets[10, 1])  # root height over a flat foot with a straight leg
        for a, b in segments:  # designed heights about standing height
            if np.isfinite(designed[a:b]).all():
                root[a:b, 1] = stand[a:b] + designed[a:b]
        R, root, c4, pitch = lock_feet(offsets, R, root + extra, rel, G, contacts, pitch,
                                       fps, segments)
        pos = kin.fk(PARENTS, offsets, R, root)
        R = kin.from_soa(R)
        for i, (a, b) in zip(group, segments):
            out[i] = _finish(preps[i], R[a:b], root[a:b], c4[a:b], pos[a:b], contacts[a:b], pitch[a:b])
    return out


def generate_clip(content: str, style: str = "neutral", substyle: str | None = None, *,
                  seed: int = 0, index: int = 0, fps: float = 20.0, duration: float | None = None,
                  intensity: float = 1.0, canonical: bool = True, style_params: dict | None = None,
                  content_params: dict | None = None) -> SynthClip:
    """Generate one clip; everything random comes from np.random.default_rng([seed, index]).

    style_params / content_params override drawn parameters (see styles.PARAMS, sample_content).
    canonical=False keeps the world placement (random heading and start) instead of HumanML3D's.
    """
    return generate_clips([dict(content=content, style=style, substyle=substyle, seed=seed,
                                index=index, fps=fps, duration=duration, intensity=intensity,
                                canonical=canonical, style_params=style_params,
                                content_params=content_params)])[0]


# ---------------------------------------------------------------- checks
def plausibility(positions, contacts, fps: float, parents=None) -> dict:
    """What the plausibility tests bound: slide of contact joints per frame (m), floor contact,
    bone-length spread (m), the fastest joint (m/s). contacts: (T, 4) for joints 7, 10, 8, 11."""
    p = np.asarray(positions, float)
    c = np.asarray(contacts, bool)
    feet = p[:, list(FOOT_CONTACT_JOINTS)]
    both = c[1:] & c[:-1]
    step = np.linalg.norm(feet[1:, :, [0, 2]] - feet[:-1, :, [0, 2]], axis=-1)
    lowest = p[:, list(FOOT_CONTACT_JOINTS), 1].min(1)
    contact_height = np.abs(feet[..., 1])[c] if c.any() else np.zeros(1)
    toe_c = c[:, [1, 3]]
    toe_h = feet[:, [1, 3], 1][toe_c] if toe_c.any() else np.zeros(1)
    bl = positions_bone_lengths(p, PARENTS if parents is None else parents)
    speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * fps
    return {
        "max_contact_slide": float(step[both].max()) if both.any() else 0.0,
        "max_contact_toe_height": float(np.abs(toe_h).max()),
        "max_contact_height": float(contact_height.max()),
        "min_foot_height": float(lowest.min()),
        "bone_length_spread": float((bl.max(0) - bl.min(0)).max()),
        "max_joint_speed": float(speed.max()) if len(speed) else 0.0,
        "contact_fraction": float(c[:, [1, 3]].any(1).mean()),
    }
