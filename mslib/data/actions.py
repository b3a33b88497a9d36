"""Joint-angle plans of actions over a standing base: stand, punch, kick, wave, jump.

Each action is a few keyframed tracks (smoothstep between keys) on top of an idle stance whose feet
stay planted (contacts True) — except the kicking foot while it kicks and both feet in a jump's
flight. Timing scales with the style's `action_speed`, ranges with `action_amp`; actions repeat
with idle gaps until the clip is full.

Jumps are the exception: real capture (the Xia train split) shows every style's jump taking about
as long (1.0–1.5 s from the crouch to the landing) and the pelvis rising and falling about as far
(0.4–0.7 leg lengths), so a jump's timing and height do not follow the style's tempo and range —
the style shows in its posture and in the fitted per-joint layer (joint_moments.py). A real crouch
also tips the pelvis forward (the trunk then leans less at the spine), and a real flight tucks the
legs and swings the arms high: JUMP_KEYS and PELVIS_TILT hold those numbers.
"""
from __future__ import annotations

import numpy as np

from .body import LEFT, RIGHT, Angles, keyframes, shaped, slow_noise
from .gait import Plan, apply_posture, stance_abduction


# the jump's key angles (degrees): the crouch, the flight's tuck and the landing's absorption; arm flexion
# back in the crouch and up in the flight
JUMP_KEYS = {"crouch_hip": 60.5, "crouch_knee": 93.5, "crouch_lean": 30.8, "tuck_hip": 49.0, "tuck_knee": 84.0,
             "absorb_hip": 55.0, "absorb_knee": 82.5, "absorb_lean": 27.5, "arm_back": -52.0, "arm_up": 110.5}
PELVIS_TILT = 30.0  # degrees of forward pelvis tilt at the deepest crouch (the hips flex that much less)
SPINE_SHARE = 0.2  # of that tilt the trunk keeps: the spine leans 0.8 × the tilt less


def _side(name: str) -> int:
    return LEFT if name == "left" else RIGHT


def _stand(T, fps, rng, sp, leg, stagger_front=None):
    """Idle stance: feet apart, slow weight shifts, the style's rhythm (bounce, sway, nod) and
    posture; returns (angles, t, contacts, foot pitch)."""
    t = np.arange(T) / fps
    ang = Angles(T)
    abd = stance_abduction(sp["width"], leg, 0.10)
    lean_side = float(rng.choice([-1, 1]))  # which leg carries the weight (contrapposto)
    shift = slow_noise(rng, t, 1.5, period=5.0) + 1.2 * (sp["hip_sway"] - 1.0) * lean_side
    beat = 2 * np.pi * 1.6 * sp["cadence"] * t + rng.uniform(0, 2 * np.pi)  # a body rhythm
    bounce = 6.0 * sp["bounce"] * (0.5 - 0.5 * np.cos(2 * beat))
    for side in (LEFT, RIGHT):
        ang.hip(side, abduct=abd, out=sp["toe_out"], flex=0.5 * bounce)
        free = (side == LEFT) == (lean_side > 0)  # the unweighted leg relaxes its knee
        ang.knee(side, flex=bounce + (4.0 * max(sp["hip_sway"] - 1.0, 0.0) if free else 0.0))
        ang.add(1 if side == LEFT else 2, roll=shift)  # both feet sideways: the pelvis shifts
        if stagger_front is not None:
            ang.hip(side, flex=10.0 if side == stagger_front else -7.0,
                    out=0.0 if side == stagger_front else 15.0)
    ang.pelvis(obliquity=-0.8 * shift + 0.5 * sp["sway"] * np.sin(beat / 2))
    ang.spine(bend=sp["sway"] * np.sin(beat / 2))
    ang.neck(pitch=0.7 * sp["head_bob"] * np.sin(2 * beat))
    contacts = np.ones((T, 2), bool)
    return ang, t, contacts, np.zeros((T, 2))


def _tempo(sp):
    return float(np.clip(sp["action_speed"] * np.sqrt(sp["cadence"]), 0.4, 1.8))


def _amp(sp):
    return float(np.clip(sp["action_amp"], 0.4, 1.6))


def _idle_arms(ang, t, rng, sp):
    for side in (LEFT, RIGHT):
        if sp["akimbo"] > 0.5:
            continue
        ang.shoulder(side, flex=3 + slow_noise(rng, t, 2.0 * (0.5 + sp["arm_swing"]), period=3.0))


def stand(T, fps, rng, sp, cp, leg) -> Plan:
    """Stand still, shift weight and look around."""
    ang, t, contacts, pitch = _stand(T, fps, rng, sp, leg)
    keys, tk = [(0.0, 0.0)], rng.uniform(0.3, 1.0)
    while tk < t[-1]:
        keys.append((tk, rng.uniform(-40, 40)))
        tk += rng.uniform(0.6, 1.4) / _tempo(sp) + 0.4
    ang.neck(turn=keyframes(t, keys), pitch=keyframes(t, [(k, rng.uniform(-8, 8)) for k, _ in keys]))
    apply_posture(ang, sp, t, rng)
    _idle_arms(ang, t, rng, sp)
    return Plan(ang, np.full(T, rng.uniform(-np.pi, np.pi)), contacts, pitch)


def punch(T, fps, rng, sp, cp, leg) -> Plan:
    """Guard up, then punches with one hand (straight punches with a trunk rotation)."""
    hand = _side(cp["side"])
    ang, t, contacts, pitch = _stand(T, fps, rng, sp, leg, stagger_front=1 - hand)
    tempo, amp = _tempo(sp), _amp(sp)
    t0 = rng.uniform(0.35, 0.8)
    guard = keyframes(t, [(0.0, 0.0), (t0 - 0.05, 1.0)])
    keys, tk = [(0.0, 0.0)], t0 + rng.uniform(0.1, 0.4)
    while True:
        d = 0.6 / tempo * rng.uniform(0.9, 1.1)
        if tk + d > t[-1]:
            break
        keys += [(tk, 0.0), (tk + 0.35 * d, 1.0), (tk + 0.45 * d, 1.0), (tk + d, 0.0)]
        tk += d + rng.uniform(0.15, 0.6) / tempo
    ext = shaped(keyframes(t, keys), sp["jerk"]) if len(keys) > 1 else np.zeros(T)
    sgn = 1.0 if hand == RIGHT else -1.0
    for side in (LEFT, RIGHT):
        e = ext if side == hand else 0.0
        ang.shoulder(side, flex=guard * 50 + e * 38 * amp + (1 - guard) * 0.7 * sp["lean"],
                     abduct=guard * 8 - e * 12,
                     twist=-45 * guard * (1 - e) - 50 * e)
        ang.elbow(side, flex=guard * 115 * (1 - e) + e * 8)
    ang.spine(turn=sgn * (12 * guard + 20 * amp * sp["twist"] ** 0.5 * ext), lean=5 * ext)
    ang.neck(turn=-sgn * (10 * guard + 14 * amp * ext))
    apply_posture(ang, sp, t, rng, arms=False)
    return Plan(ang, np.full(T, rng.uniform(-np.pi, np.pi)), contacts, pitch)


def kick(T, fps, rng, sp, cp, leg) -> Plan:
    """Front kicks with one leg: weight onto the other foot, chamber, snap, retract, put down."""
    kleg = _side(cp["side"])
    ang, t, contacts, pitch = _stand(T, fps, rng, sp, leg)
    tempo, amp = min(_tempo(sp), 1.25), _amp(sp)
    hip_k, knee_k, ank_k, shift_k, up_k = [(0.0, 0.0)], [(0.0, 0.0)], [(0.0, 0.0)], [(0.0, 0.0)], [(0.0, 0.0)]
    tk = rng.uniform(0.4, 0.9)
    airborne = np.zeros(T, bool)
    while True:
        d = 1.15 / tempo * rng.uniform(0.9, 1.1)
        if tk + d + 0.35 > t[-1]:
            break
        shift_k += [(tk - 0.3, 0.0), (tk, 1.0), (tk + d, 1.0), (tk + d + 0.3, 0.0)]
        up_k += [(tk, 0.0), (tk + 0.3 * d, 1.0), (tk + 0.7 * d, 1.0), (tk + d, 0.0)]
        high = min(amp * (0.7 + 0.3 * sp["knee_lift"]), 1.15)
        hip_k += [(tk, 0.0), (tk + 0.3 * d, 65 * high), (tk + 0.5 * d, 78 * high),
                  (tk + 0.72 * d, 45 * high), (tk + d, 0.0)]
        knee_k += [(tk, 0.0), (tk + 0.3 * d, 100), (tk + 0.5 * d, 12), (tk + 0.7 * d, 85),
                   (tk + d, 0.0)]
        ank_k += [(tk, 0.0), (tk + 0.3 * d, 25), (tk + 0.8 * d, 25), (tk + d, 0.0)]
        airborne |= (t > tk + 0.06 * d) & (t < tk + 0.96 * d)
        tk += d + 0.35 + rng.uniform(0.3, 1.0) / tempo
    stance = 1 - kleg
    toward_stance = 1.0 if stance == RIGHT else -1.0  # raw hip roll moving the pelvis over it
    sh = keyframes(t, sorted(shift_k))
    for side in (LEFT, RIGHT):
        ang.add(1 if side == LEFT else 2, roll=-toward_stance * 5.0 * sh)
    ang.pelvis(obliquity=toward_stance * 3.0 * sh)
    ang.hip(kleg, flex=keyframes(t, hip_k))
    ang.knee(kleg, flex=keyframes(t, knee_k))
    ang.ankle(kleg, plantar=keyframes(t, ank_k))
    up = keyframes(t, up_k)
    ang.spine(lean=-12 * amp * up)
    for side in (LEFT, RIGHT):
        ang.shoulder(side, abduct=25 * up, flex=20 * up)
        ang.elbow(side, flex=50 * up)
    contacts[:, kleg] = ~airborne
    apply_posture(ang, sp, t, rng)
    return Plan(ang, np.full(T, rng.uniform(-np.pi, np.pi)), contacts, pitch)


def wave(T, fps, rng, sp, cp, leg) -> Plan:
    """Raise one hand and wave it side to side, lower it, repeat after a pause."""
    hand = _side(cp["side"])
    ang, t, contacts, pitch = _stand(T, fps, rng, sp, leg)
    tempo, amp = _tempo(sp), _amp(sp)
    keys, tk = [(0.0, 0.0)], rng.uniform(0.2, 0.7)
    while tk + 1.6 < t[-1]:
        hold = min(rng.uniform(1.2, 2.8), t[-1] - tk - 0.9)
        keys += [(tk, 0.0), (tk + 0.45 / tempo, 1.0), (tk + 0.45 / tempo + hold, 1.0),
                 (tk + 0.9 / tempo + hold, 0.0)]
        tk += 0.9 / tempo + hold + rng.uniform(0.4, 1.2)
    raised = keyframes(t, keys)
    osc = np.sin(2 * np.pi * 2.0 * tempo * t) * raised
    ang.shoulder(hand, abduct=105 * amp * raised, flex=25 * raised, twist=60 * raised + 22 * amp * osc)
    ang.elbow(hand, flex=70 * raised)
    ang.neck(turn=(18 if hand == LEFT else -18) * raised)
    apply_posture(ang, sp, t, rng)
    _idle_arms(ang, t, rng, sp)
    return Plan(ang, np.full(T, rng.uniform(-np.pi, np.pi)), contacts, pitch)


def jump(T, fps, rng, sp, cp, leg) -> Plan:
    """Crouch (the pelvis tips forward), push off (heels up, arms swing up), fly (ballistic root, legs
    tucked), land, absorb, recover; the same timing and height for every style (see the module docstring)."""
    ang, t, contacts, pitch = _stand(T, fps, rng, sp, leg)
    tempo = 1.0
    height = float(np.clip(cp["height"], 0.06, 0.5))
    dist = float(cp["distance"])
    tau = np.sqrt(8 * height / 9.81)
    tracks = {k: [(0.0, 0.0)] for k in ("hip", "knee", "lean", "arm", "ankle", "fwd")}
    foot_p = [(0.0, 0.0)]
    air = np.zeros(T, bool)
    tk = rng.uniform(0.25, 0.6)
    if tk + 1.42 / tempo + tau > t[-1]:  # a short clip: one quicker, lower jump that fits
        height = min(height, 0.12)
        tau = np.sqrt(8 * height / 9.81)
        tk = 0.1
        tempo = max(tempo, 1.42 / max(t[-1] - tk - tau - 0.05, 0.3))
    n_jumps = 0
    while True:
        c, p = 0.45 / tempo, 0.22 / tempo
        to = tk + c + p
        la = to + tau
        end = la + (0.3 + 0.45) / tempo
        if n_jumps > 0 and end > t[-1]:
            break
        ab, rc = la + 0.3 / tempo, end
        k = JUMP_KEYS
        tracks["hip"] += [(tk, 0), (tk + c, k["crouch_hip"]), (to, -5), (to + 0.5 * tau, k["tuck_hip"]), (la, 15),
                          (ab, k["absorb_hip"]), (rc, 0)]
        tracks["knee"] += [(tk, 0), (tk + c, k["crouch_knee"]), (to, 3), (to + 0.5 * tau, k["tuck_knee"]), (la, 18),
                           (ab, k["absorb_knee"]), (rc, 0)]
        tracks["lean"] += [(tk, 0), (tk + c, k["crouch_lean"]), (to, 6), (la, 10), (ab, k["absorb_lean"]), (rc, 0)]
        tracks["arm"] += [(tk, 0), (tk + 0.7 * c, k["arm_back"]), (to + 0.3 * tau, k["arm_up"]), (la, 40), (ab, 25),
                          (rc, 0)]
        tracks["ankle"] += [(to, 0), (to + 0.2 * tau, 25), (la, 25), (la + 0.05, 0)]
        tracks["fwd"] += [(to - 0.12, 0), (la + 0.08, 1.0)]
        foot_p += [(tk + c, 0.0), (to, 45.0), (to + 1e-3, 25.0), (la, 25.0), (la + 0.08, 0.0)]
        air |= (t >= to) & (t < la)
        n_jumps += 1
        tk = rc + rng.uniform(0.2, 0.8)
    lean = keyframes(t, tracks["lean"])
    tilt = PELVIS_TILT * lean / JUMP_KEYS["crouch_lean"]  # the pelvis tips forward with the crouch
    ang.pelvis(tilt=tilt)
    ang.hip(LEFT, flex=keyframes(t, tracks["hip"]) - tilt)  # the thighs keep their angle in the world
    ang.hip(RIGHT, flex=keyframes(t, tracks["hip"]) - tilt)
    for side in (LEFT, RIGHT):
        ang.knee(side, flex=keyframes(t, tracks["knee"]))
        ang.ankle(side, plantar=keyframes(t, tracks["ankle"]))
        ang.shoulder(side, flex=keyframes(t, tracks["arm"]), abduct=5)
        ang.elbow(side, flex=20)
    ang.spine(lean=lean - (1 - SPINE_SHARE) * tilt)
    ang.neck(pitch=-0.6 * lean)
    apply_posture(ang, sp, t, rng)
    contacts[air] = False
    fp = keyframes(t, foot_p)
    pitch[:] = np.where(air, 0.0, fp)[:, None]
    heading = np.full(T, rng.uniform(-np.pi, np.pi))
    # forward travel of a jump: the stance-derived root has none, so it is added
    fwd = np.zeros(T)
    acc = 0.0
    keys = tracks["fwd"]
    for k in range(1, len(keys), 2):
        seg = keyframes(t, [keys[k], keys[k + 1]])
        fwd += dist * seg
        acc += dist
    offset = np.stack([np.sin(heading) * fwd, np.zeros(T), np.cos(heading) * fwd], -1)
    return Plan(ang, heading, contacts, pitch, {"n_jumps": n_jumps, "height": height,
                                                 "distance": dist}, root_offset=offset)
