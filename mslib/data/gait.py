"""Phase-driven joint-angle plans: style posture and locomotion (walk, run, turn, side step, backward).

A *plan* is what the generator needs before forward kinematics: joint angles over time, the root
heading, which foot is in contact when, and the desired foot pitch during contact (heel rise).
Locomotion is driven by a gait phase φ(t) (one cycle = two steps): each leg has its own phase u,
is in stance while u < β (the duty factor) and swings otherwise. During stance the thigh moves
linearly from front to back (so the body moves at an even speed), during swing it returns along a
smooth Hermite curve; knee, pelvis, trunk and arm curves are periodic bumps in the same phase.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .body import LEFT, RIGHT, Angles, bump, keyframes, shaped, slow_noise, tremor


THORAX_TURN, TRUNK_ROLL = 6.0, -5.0  # degrees every gait adds (real upper bodies turn and roll more)


@dataclass
class Plan:
    """Joint angles, root heading (radians), contacts (T, 2: left, right), foot pitch in contact,
    an optional extra root translation (T, 3) added to the stance-derived one (e.g. a jump), and an
    optional root height curve (T,) relative to standing height, replacing the stance-derived one."""

    angles: Angles
    heading: np.ndarray
    contacts: np.ndarray
    foot_pitch: np.ndarray
    info: dict = field(default_factory=dict)
    root_offset: np.ndarray | None = None
    root_height: np.ndarray | None = None  # designed height about standing (spring-mass running)


def stance_abduction(width: float, leg: float, half_width: float = 0.10) -> float:
    """Hip abduction (degrees) that puts a foot `half_width·width` m beside the midline."""
    hip_x = 0.058  # the body's hip offset from the midline
    return float(np.degrees(np.arcsin(np.clip((half_width * width - hip_x) / leg, -0.5, 0.5))))


def apply_posture(ang: Angles, sp: dict, t, rng: np.random.Generator, phase=None,
                  arms: bool = True):
    """Style posture common to every content: trunk, head, shoulders, arm carriage, tremor."""
    lean, chest = sp["lean"], sp["chest"]
    ang.pelvis(tilt=0.25 * lean)
    for side in (LEFT, RIGHT):
        ang.hip(side, flex=0.25 * lean + 0.5 * sp["knee"])
        ang.knee(side, flex=sp["knee"])
    ang.spine(lean=0.75 * lean)
    for j, w in ((3, 0.5), (6, -0.4), (9, -0.6)):
        ang.add(j, pitch=w * chest)
    trem = sp["tremor"]
    head_pitch = sp["head"] - 0.5 * lean + 0.35 * chest
    bob = 0.0 if phase is None else sp["head_bob"] * np.cos(4 * np.pi * phase)
    ang.neck(pitch=head_pitch + bob + tremor(rng, t, 0.5 * trem), tilt=sp["head_tilt"],
             turn=slow_noise(rng, t, 4.0, period=3.0) + tremor(rng, t, 0.6 * trem))
    ang.add(9, pitch=tremor(rng, t, 0.3 * trem))
    for side in (LEFT, RIGHT):
        ang.collar(side, raise_=sp["shoulder_raise"], back=sp["shoulder_back"])
        if not arms:
            continue
        if sp["akimbo"] > 0.5:
            ang.shoulder(side, flex=-12, abduct=48, twist=-35)
            ang.elbow(side, flex=105)
            continue
        ang.shoulder(side, abduct=sp["arm_out"] + tremor(rng, t, 0.4 * trem),
                     flex=0.7 * lean + tremor(rng, t, 0.8 * trem))  # arms hang toward the floor
        ang.elbow(side, flex=sp["elbow"] + tremor(rng, t, 1.2 * trem))
        ang.wrist(side, flex=10 + 0.3 * sp["elbow"])


def cadence_and_duty(content: str, speed: float, sp: dict, leg: float):
    """Step length (m), step frequency (steps/s) and duty factor of a gait at a neutral speed,
    with the style's stride and cadence multipliers applied (the speed changes with them)."""
    if content == "run":
        step0, beta = speed / (2.6 + 0.12 * speed), 0.35 + 0.03 * (2.6 - speed)
    elif content == "side_step":
        step0, beta = speed / (1.5 + 0.6 * speed), 0.62
    elif content == "walk_backward":
        step0, beta = speed / (1.3 + 0.8 * speed), 0.62
    else:  # step length grows with speed, relative to the leg (≈ 0.4 × body height when brisk)
        step0 = (0.33 + 0.21 * speed) * leg / 0.8
        beta = float(np.clip(0.62 - 0.05 * (speed - 1.2), 0.57, 0.68))
    cadence = min(speed / step0 * sp["cadence"], 3.4 if content == "run" else 2.7)
    step = step0 * sp["stride"]
    if content != "run":
        step = min(step, 0.95 * leg)
    top = 3.1 if content == "run" else 2.0  # keep styled speeds (and limb speeds) human
    step = min(step, top / cadence)
    return step, cadence, float(np.clip(beta + sp["duty"], 0.3, 0.72))


def excursion(u, u_end: float):
    """Thigh excursion: +1 → −1 linearly while the foot carries the body (u < u_end), then a
    smooth return (pre-swing and swing) with matching slopes."""
    s = np.empty_like(u)
    st = u < u_end
    s[st] = 1 - 2 * u[st] / u_end
    w = (u[~st] - u_end) / (1 - u_end)
    m = max(-2 * (1 - u_end) / u_end, -1.6)  # stance slope, per unit of the return
    h00, h10 = 2 * w ** 3 - 3 * w ** 2 + 1, w ** 3 - 2 * w ** 2 + w
    h01, h11 = -2 * w ** 3 + 3 * w ** 2, w ** 3 - w ** 2
    s[~st] = -h00 + m * h10 + h01 + m * h11
    return s


def _foot_roll(u, beta: float, content: str, step: float, sp: dict):
    """Foot pitch in stance (degrees): heel rocker after heel strike (−), flat, heel rise (+)."""
    if content == "side_step":  # a sideways step does not roll over the toes
        keys = [(0.0, 0.0), (0.7 * beta, 0.0), (beta, 12.0)]
    elif content == "walk_backward":
        keys = [(0.0, 10.0), (0.1 * beta / 0.62, 0.0), (0.45 * beta / 0.62, 0.0), (beta, 20.0)]
    elif content == "run" or beta < 0.53:  # gaits with a flight phase land flat, push off the toes
        keys = [(0.0, 0.0), (0.4 * beta, 0.0), (beta, 50.0)]
    else:
        strike = 18.0 * float(np.clip(step / 0.6, 0.2, 1.2)) * min(sp["knee_lift"], 1.3)
        keys = [(0.0, -strike), (0.09, 0.0), (0.28, 0.0), (0.5, 20.0), (beta, 45.0)]
    return np.where(u < beta, keyframes(u, keys), 0.0)


def locomotion(T: int, fps: float, rng: np.random.Generator, sp: dict, cp: dict, leg: float) -> Plan:
    """A gait plan (walk, run, turning walk, side step, backward walk) of T frames."""
    content = cp["content"]
    run = content == "run"
    t = np.arange(T) / fps
    step, cad, beta = cadence_and_duty(content, cp["speed"], sp, leg)
    f = cad / 2  # cycles per second
    phase = rng.uniform() + f * t + 0.015 * np.sin(2 * np.pi * t / rng.uniform(2.5, 4.0))
    limp = sp["limp"]
    u = np.stack([phase % 1.0, (phase + 0.5 + 0.6 * limp) % 1.0], 1)  # (T, 2) left, right
    contacts = u < beta
    u_end = min(beta, 0.5)  # the foot carries the body until the other one lands
    # foot travel relative to the hip while it carries the body (the foot's roll adds a little)
    D = 2 * step * u_end - (0.0 if run else 0.06 * min(step / 0.6, 1.2))
    amp = np.degrees(np.arcsin(np.clip(D / (2 * leg * (0.93 if run else 1.0)), 0, 0.5)))
    alpha = np.radians(cp["direction"])
    ang = Angles(T)
    swing_mid = beta + 0.3 * (1 - beta)
    small = float(np.clip(step / 0.72, 0.35, 1.3))  # small steps lift the knee less
    lift = min(sp["knee_lift"], 1.25) if run else sp["knee_lift"]
    width_abd = stance_abduction(sp["width"], leg, 0.065)
    foot_pitch = np.zeros((T, 2))
    tilt = 6.0 if run else 1.0  # the pelvis's forward tilt in this gait (the thighs compensate)
    for side in (LEFT, RIGHT):
        us = u[:, side]
        # the foot lands closer under the hip than where it leaves (more so in running)
        shorter = 1 - (1.6 * limp if side == RIGHT else 0.0)  # a limp shortens the right step
        s = (excursion(us, u_end) - (0.15 if run else 0.1)) * amp * shorter
        sw = bump(us, swing_mid, 0.12 if not run else 0.13)
        if run:
            knee = 18 + 30 * bump(us, 0.45 * beta, 0.1) + 95 * lift * sw
            hip_lift = 22 * lift * bump(us, swing_mid + 0.06, 0.13)
            ank = 8.0
        else:
            knee = ((10 + 25 * sp["bounce"]) * bump(us, 0.15 * beta, 0.08)
                    + (38 + 22 * small) * lift * sw + 6 * bump(us, 0.8, 0.05))
            hip_lift = (8 + 22 * max(lift - 1, 0)) * bump(us, swing_mid + 0.05, 0.12) * small
            ank = -6.0
        if content == "side_step":
            knee = 5 + 30 * sw * lift
            hip_lift = 10 * sw
        # sagittal excursion along the travel direction: flexion forward, raw roll sideways
        ang.hip(side, flex=np.cos(alpha) * s + hip_lift + tilt, abduct=width_abd - sp["cross"],
                out=sp["toe_out"])
        ang.add(1 if side == LEFT else 2, roll=np.sin(alpha) * s)
        # stance adduction shifts the pelvis over the stance foot (lateral sway)
        ang.hip(side, abduct=-1.6 * sp["hip_sway"] * bump(us, 0.5 * beta, 0.5 * beta / 2))
        ang.knee(side, flex=knee + (12 * limp if side == RIGHT else 0.0))
        ang.ankle(side, plantar=ank)
        foot_pitch[:, side] = _foot_roll(us, beta, content, step, sp)

    # pelvis and trunk
    uL = u[:, LEFT]
    cyc = 2 * np.pi * uL
    side_only = content == "side_step"
    twist = 0.0 if side_only else sp["twist"]
    ang.pelvis(obliquity=4.0 * sp["hip_sway"] * np.cos(cyc - 2 * np.pi * 0.3),
               turn=-4.0 * twist * np.cos(cyc) * (1.3 if run else 1.0),
               tilt=tilt + 1.5 * np.cos(2 * cyc))
    into_turn = 2.0 * np.sign(cp["curvature"]) * (abs(cp["curvature"]) > 0.1)  # lean into a curve
    ang.spine(lean=(8.0 if run else 0.0) + (3.0 if content == "walk_backward" else 0.0),
              turn=((4.0 + 5.0) * twist + THORAX_TURN * (not side_only)) * np.cos(cyc) * (1.3 if run else 1.0),
              bend=(sp["sway"] + TRUNK_ROLL) * np.cos(cyc - 2 * np.pi * 0.3) + into_turn)
    apply_posture(ang, sp, t, rng, phase=phase)

    # arms swing opposite to the legs
    arm_amp = (30.0 * min(sp["arm_swing"], 1.7) if run
               else 16.0 * float(np.clip(small, 0.5, 1.2)) * sp["arm_swing"])
    if side_only:
        arm_amp *= 0.25
    for side in (LEFT, RIGHT):
        if sp["akimbo"] > 0.5:
            continue
        if sp["cane"] > 0.5 and side == RIGHT:
            ang.shoulder(side, flex=28 + 4 * np.cos(2 * np.pi * uL), abduct=4)
            ang.elbow(side, flex=15)
            continue
        c = shaped(-np.cos(2 * np.pi * (u[:, side] - 0.04)), sp["jerk"])
        ang.shoulder(side, flex=arm_amp * c + (8.0 if run else 2.0))
        bend = (70.0 if run else 0.0) + (0.6 if run else 0.7) * arm_amp * (0.5 + 0.5 * c)
        ang.elbow(side, flex=bend)
    if sp["cane"] > 0.5:
        ang.spine(bend=-4.0)

    # heading: a gentle or a tight curve (curvature × distance travelled)
    expected_speed = step * cad
    heading = rng.uniform(-np.pi, np.pi) + cp["curvature"] * expected_speed * t
    info = {"cadence": cad, "duty": beta, "step_length": step, "phase": phase}
    height = _spring_mass(phase, beta, f) - 0.05 if beta < 0.5 else None
    return Plan(ang, heading, contacts, foot_pitch, info, root_height=height)


def _spring_mass(phase, beta: float, f: float):
    """Root height (m, about 0) of a gait with flight: a sine dip in stance, a parabola in flight,
    velocities matching at touch-down and take-off."""
    psi = (2 * phase) % 1.0  # step phase: stance while psi < 2β
    tau = (1 - 2 * beta) / (2 * f)  # flight time, s
    v_up = 9.81 * tau / 2
    dip = v_up * beta / (np.pi * f)
    s = (psi - 2 * beta) / (2 * f)
    flight = v_up * s - 0.5 * 9.81 * s ** 2
    return np.where(psi < 2 * beta, -dip * np.sin(np.pi * psi / (2 * beta)), flight)
