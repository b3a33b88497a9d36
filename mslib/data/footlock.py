"""Physical plausibility by construction: root from the stance foot, then feet locked by leg IK.

Two steps turn a joint-angle plan into a grounded motion:

A planted foot rolls: its pitch in contact (`foot_pitch`, degrees) is negative while it rocks on
the heel after heel strike (toe up, the *heel point* below and behind the ankle is the pivot), zero
when flat, positive while it rolls over the toe joint (heel up, the toe is the pivot).

1. `anchor_root` — the pose is computed with the root at the origin; the foot that carries the
   body (of the feet down, the one that landed last) must not move in the world at its pivot, so
   the root moves by minus the pivot's displacement, and its height puts the pivot on y = 0.
   Without contact (run, jump) the root keeps the mean stance velocity and follows a ballistic
   arc (gravity 9.81 m/s²) between contacts. Derived this way the root changes velocity abruptly
   at every change of carrying foot, which real capture does not do (its pelvis jerk is a quarter
   of that), so the path is then low-passed (`ROOT_SMOOTHING`); step 2 re-plants the feet exactly.
2. `lock_feet` — every contact interval gets an anchor (where the flat foot's toe is, on the
   floor) and a heading; the foot's orientation follows the pitch profile about its pivot, and an
   analytic two-bone IK (thigh, shank) puts the ankle where that needs it, exactly, the knee bent
   toward the front of the thigh (`KNEE_POLE_FORWARD`) as a human knee only can. Outside contact the correction fades over a few frames and the swing foot is kept above the floor.
   The root is lowered where a leg could not reach its anchor.

Both work on a *batch*: several clips concatenated along time, `segments` giving each clip's
(start, stop) frames; nothing crosses a segment boundary, so a clip's result does not depend on
the other clips of its batch. Rotations are in kin's layout (J, 3, 3, N) and offsets per frame
(J, 3, N): each clip has its own body.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d, maximum_filter1d

from ..motion import rotations as rot
from . import kin
from .body import LEG

GRAVITY = 9.81
REACH = 0.995  # a planted leg straightens to at most this fraction of thigh + shank
KNEE_POLE_FORWARD = 1.0  # m: the IK bends each knee toward a point this far in front of the planned knee
ROOT_SMOOTHING = (0.14, 0.04)  # s: Gaussian σ of the root path across (x, z) and up (y)


def foot_yaw(G_ankle) -> np.ndarray:
    """Heading (radians, about +Y from +Z) of feet from their ankles' global rotations (3, 3, N)."""
    return np.arctan2(G_ankle[0, 2], G_ankle[2, 2])


def runs(mask) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the runs of True in a 1-D boolean array (stop exclusive)."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(np.diff(m.astype(np.int8)))
    return list(zip(edges[::2], edges[1::2]))


def heel_vector(o_toe):
    """The heel point in the foot's frame (3, N): level with the flat foot's toe, behind the ankle."""
    length = np.sqrt((o_toe ** 2).sum(0))
    return np.stack([np.zeros_like(length), o_toe[1], -0.3 * length])


def _run_ids(mask, seg_first):
    """Id per frame of its contact run (runs break at segment starts), −1 outside contact."""
    start = mask & ~np.concatenate([[False], mask[:-1]])
    start |= mask & seg_first
    ids = np.cumsum(start) - 1
    return np.where(mask, ids, -1), int(start.sum())


def _nearest_contact(mask, seg_first, seg_last):
    """Per frame: the nearest contact frame of the same segment and the distance (inf if none)."""
    idx = np.arange(len(mask), dtype=float)
    last = np.maximum.accumulate(np.where(mask, idx, np.where(seg_first, idx - 0.5, -np.inf)))
    nxt = np.minimum.accumulate(np.where(mask, idx, np.where(seg_last, idx + 0.5, np.inf))[::-1])[::-1]
    d_last = np.where(last == np.floor(last), idx - last, np.inf)
    d_next = np.where(nxt == np.floor(nxt), nxt - idx, np.inf)
    near = np.where(d_last <= d_next, last, nxt)
    near = np.where(np.isfinite(near) & (near == np.floor(near)), near, 0).astype(int)
    return near, np.minimum(d_last, d_next)


def _seg_flags(segments, N):
    first, last = np.zeros(N, bool), np.zeros(N, bool)
    for a, b in segments:
        first[a], last[b - 1] = True, True
    return first, last


def _unit_cols(v):
    """Columns of v (3, N) made unit length."""
    return v / np.maximum(np.sqrt((v * v).sum(0)), 1e-12)


def _fill_flight(vel, has):
    """Rows without a planted foot take the mean velocity of the neighbouring stance runs."""
    if has.all():
        return vel
    if not has.any():
        return np.zeros_like(vel)
    vel = vel.copy()
    means = [(a, b, vel[a:b].mean(0)) for a, b in runs(has)]
    for a, b in runs(~has):
        near = [m for (s, e, m) in means if e == a or s == b]
        vel[a:b] = np.mean(near, axis=0)
    return vel


def _ballistic_fill(y, has, fps):
    """Fill frames without contact by parabolas under gravity joining the neighbouring contacts."""
    y = y.copy()
    for a, b in runs(~has):
        if a == 0 and b == len(y):
            y[:] = 0.0
        elif a == 0:
            y[a:b] = y[b]
        elif b == len(y):
            y[a:b] = y[a - 1]
        else:
            t0, t1 = a - 1, b
            tt = np.arange(a, b)
            lin = y[t0] + (y[t1] - y[t0]) * (tt - t0) / (t1 - t0)
            y[a:b] = lin + 0.5 * GRAVITY * (tt - t0) * (t1 - tt) / fps ** 2
    return y


def _leading(c):
    """(T, 2) contact feet that carry the root: of the feet down, the one that landed last
    (both when they landed together)."""
    T = len(c)
    idx = np.arange(T)
    start = np.empty((T, 2))
    for side in (0, 1):
        begin = c[:, side] & ~np.concatenate([[False], c[:-1, side]])
        start[:, side] = np.maximum.accumulate(np.where(begin, idx, -1))
    start = np.where(c, start, -np.inf)
    return c & (start == start.max(1, keepdims=True))


def anchor_root(parents, offsets, R, contacts, foot_pitch, fps: float, segments):
    """Root positions (N, 3) keeping the carrying toe still and on the floor (`_leading`).

    Also returns the root-relative positions (N, J, 3) and global rotations (J, 3, 3, N)."""
    N = R.shape[-1]
    rel, G = kin.fk(parents, offsets, R, np.zeros((N, 3)), return_globals=True)
    toes, heels = [], []
    for side in (0, 1):
        _, _, ankle, toe = LEG[side]
        Gd = kin.yaw_pitch(foot_yaw(G[ankle]), np.deg2rad(foot_pitch[:, side]))
        toes.append(rel[:, ankle] + kin.mv(Gd, offsets[toe]).T)
        heels.append(rel[:, ankle] + kin.mv(Gd, heel_vector(offsets[toe])).T)
    toes, heels = np.stack(toes, 1), np.stack(heels, 1)  # (N, 2, 3)
    on_heel = foot_pitch < 0
    pivot = np.where(on_heel[..., None], heels, toes)
    root = np.zeros((N, 3))
    for a, b in segments:
        c = contacts[a:b]
        lead = _leading(c)
        both = lead[1:] & c[:-1]
        n = both.sum(1)
        heel_pair = (on_heel[a:b][1:] | on_heel[a:b][:-1])[..., None]  # one pivot for both frames
        disp = -np.where(heel_pair, heels[a + 1:b] - heels[a:b - 1], toes[a + 1:b] - toes[a:b - 1])
        vel = (disp[..., [0, 2]] * both[..., None]).sum(1) / np.maximum(n, 1)[:, None]
        root[a + 1:b, [0, 2]] = np.cumsum(_fill_flight(vel, n > 0), 0)
        low = np.where(lead, pivot[a:b, :, 1], np.inf).min(1)
        has = c.any(1)
        root[a:b, 1] = _ballistic_fill(np.where(has, -low, 0.0), has, fps)
        across, up = ROOT_SMOOTHING
        root[a:b, [0, 2]] = gaussian_filter1d(root[a:b, [0, 2]], across * fps, axis=0, mode="nearest")
        root[a:b, 1] = gaussian_filter1d(root[a:b, 1], up * fps, mode="nearest")
    return root, rel, G


def _roll_to_reach(toe_anchor, heel_to_toe, yaw, pitch, o_toe, hip, reach, iters: int = 10):
    """Roll planted feet further about their pivot (heel up on the toe, toe up on the heel) where
    the leg could not reach the ankle otherwise; returns the pitch, ankle goals and orientations.
    Only feet already rolling do (a flat foot stays flat: the root is lowered for it instead)."""
    on_heel = pitch < 0
    pivot = np.where(on_heel[:, None], toe_anchor - heel_to_toe, toe_anchor)
    v = np.where(on_heel, heel_vector(o_toe), o_toe)

    def lack(p, k):
        ank = pivot[k] - kin.mv(kin.yaw_pitch(yaw[k], np.deg2rad(p)), v[:, k]).T
        return np.linalg.norm(ank - hip[k], axis=-1) - reach[k]

    bad = np.flatnonzero((lack(pitch, slice(None)) > 0) & (pitch != 0))
    if len(bad):  # bisection between the planned pitch and the furthest roll
        pitch = pitch.copy()
        lo, hi = pitch[bad], np.where(on_heel[bad], np.minimum(pitch[bad], -25.0), np.maximum(pitch[bad], 50.0))
        for _ in range(iters):
            mid = 0.5 * (lo + hi)
            short = lack(mid, bad) > 0
            lo, hi = np.where(short, mid, lo), np.where(short, hi, mid)
        pitch[bad] = hi
    Gd = kin.yaw_pitch(yaw, np.deg2rad(pitch))
    return pitch, pivot - kin.mv(Gd, v).T, Gd


def _two_bone_ik(H, K_pole, A, l1, l2):
    """Knee and ankle positions (N, 3) reaching from hip H toward A, knee on the side of K_pole."""
    d = A - H
    dist = np.linalg.norm(d, axis=-1)
    u = d / np.maximum(dist, 1e-9)[:, None]
    dist = np.clip(dist, np.abs(l1 - l2) + 1e-6, (l1 + l2) * (1 - 1e-7))
    pole = K_pole - H
    w = pole - (pole * u).sum(-1, keepdims=True) * u
    w = w / np.maximum(np.linalg.norm(w, axis=-1, keepdims=True), 1e-12)
    a = (l1 ** 2 - l2 ** 2 + dist ** 2) / (2 * dist)
    h = np.sqrt(np.maximum(l1 ** 2 - a ** 2, 0.0))
    return H + a[:, None] * u + h[:, None] * w, H + dist[:, None] * u


def _blend(G_fk, G_near, w):
    """G_near where w = 1, G_fk where w = 0, slerp between (all (3, 3, N))."""
    out = np.where(w >= 1.0, G_near, G_fk)
    mid = (w > 0) & (w < 1)
    if mid.any():
        qa = rot.matrix_to_quat(kin.from_soa(G_fk[..., mid]))
        qb = rot.matrix_to_quat(kin.from_soa(G_near[..., mid]))
        out[..., mid] = kin.to_soa(rot.quat_to_matrix(rot.quat_slerp(qa, qb, w[mid])))
    return out


def _solve_leg(H, K_fk, A, G0, G_hip, R_knee, R_ankle, o_knee, o_ankle, o_toe, G_near, w):
    """Two-bone IK of one leg toward ankle goals A (N, 3); local hip, knee and ankle rotations
    (3, 3, N each), the ankle and the toe positions reached (N, 3)."""
    l1, l2 = np.sqrt((o_knee ** 2).sum(0)), np.sqrt((o_ankle ** 2).sum(0))
    # bend toward the front of the thigh (its +Z, the body faces +Z at rest): a planned knee behind the
    # hip–ankle line — a nearly straight stance leg under a tilted pelvis — would otherwise bend it backward
    forward = kin.mv(G_hip, np.array([0.0, 0.0, 1.0])[:, None] * np.ones_like(l1)).T  # (N, 3)
    K_new, A_new = _two_bone_ik(H, K_fk + KNEE_POLE_FORWARD * forward, A, l1, l2)
    G_hip_new = kin.mm(kin.between(_unit_cols(kin.mv(G_hip, o_knee)), _unit_cols((K_new - H).T)), G_hip)
    G_knee = kin.mm(G_hip_new, R_knee)
    G_knee = kin.mm(kin.between(_unit_cols(kin.mv(G_knee, o_ankle)), _unit_cols((A_new - K_new).T)), G_knee)
    G_foot = _blend(kin.mm(G_knee, R_ankle), G_near, w)
    toe = A_new + kin.mv(G_foot, o_toe).T
    rots = (kin.mm(kin.tr(G0), G_hip_new), kin.mm(kin.tr(G_hip_new), G_knee), kin.mm(kin.tr(G_knee), G_foot))
    return rots, A_new, toe


def lock_feet(offsets, R, root, rel, G, contacts, foot_pitch, fps: float, segments,
              blend_s: float = 0.12, clearance=(0.004, 0.02)):
    """Lock contact feet exactly (toe anchored, foot orientation fixed) by two-bone leg IK.

    rel and G are the root-relative positions and global rotations of R (from anchor_root).
    clearance: the swing foot's lowest joint stays this high (m) next to a contact and, rising
    over `blend_s`, at the second value in mid-swing; a swing foot moving over 1.5 mm per frame
    stays at least 1.2 cm up.
    Returns (local_rotations, root, contacts4, foot_pitch); contacts4 (N, 4) flags joints 7, 10,
    8, 11 while they are planted (a toe unless the foot rocks on its heel, an ankle while the foot
    is flat); foot_pitch is the pitch in contact after any extra roll the legs needed."""
    R, root, foot_pitch = R.copy(), root.copy(), np.array(foot_pitch, float)
    N = R.shape[-1]
    P = rel + root[:, None, :]
    nb = max(1.0, blend_s * fps)
    first, last = _seg_flags(segments, N)
    eye = np.broadcast_to(np.eye(3)[:, :, None], (3, 3, N))
    legs = []
    for side in (0, 1):
        _, _, ankle, toe = LEG[side]
        c = contacts[:, side]
        ids, n = _run_ids(c, first)
        Gdes = eye.copy()
        A_goal = P[:, ankle].copy()
        if n:
            yaw = foot_yaw(G[ankle])
            sel = ids[c]
            cnt = np.bincount(sel, minlength=n)
            mean_yaw = np.arctan2(np.bincount(sel, np.sin(yaw[c]), n), np.bincount(sel, np.cos(yaw[c]), n))
            pitch = foot_pitch[c, side]
            Gd = kin.yaw_pitch(mean_yaw[sel], np.deg2rad(pitch))
            o_toe = offsets[toe][:, c]
            heel_to_toe = kin.mv(kin.rot_y(mean_yaw[sel]), o_toe - heel_vector(o_toe)).T
            pivot_vec = kin.mv(Gd, np.where(pitch < 0, heel_vector(o_toe), o_toe)).T
            # where the flat foot's toe would be, from the pivot (toe, or heel + flat heel→toe)
            toe_eq = P[c, ankle] + pivot_vec + np.where((pitch < 0)[:, None], heel_to_toe, 0.0)
            anchor = np.stack([np.bincount(sel, toe_eq[:, k], n) / cnt for k in range(3)], -1)
            anchor[:, 1] = 0.0
            hip = P[c, LEG[side][0]]
            reach = REACH * (np.sqrt((offsets[LEG[side][1]][:, c] ** 2).sum(0))
                            + np.sqrt((offsets[ankle][:, c] ** 2).sum(0)))
            pitch, ankle_goal, Gd = _roll_to_reach(anchor[sel], heel_to_toe, mean_yaw[sel], pitch,
                                                   o_toe, hip, reach)
            foot_pitch[c, side] = pitch
            Gdes[..., c] = Gd
            A_goal[c] = ankle_goal
        legs.append((c, Gdes, A_goal))

    # lower the root where a planted leg could not reach its ankle goal
    need = np.zeros(N)
    for side, (c, _, A_goal) in enumerate(legs):
        hip, knee, ankle, _ = LEG[side]
        reach = REACH * (np.sqrt((offsets[knee] ** 2).sum(0)) + np.sqrt((offsets[ankle] ** 2).sum(0)))
        d = A_goal - P[:, hip]
        lack = -d[:, 1] - np.sqrt(np.maximum(reach ** 2 - d[:, 0] ** 2 - d[:, 2] ** 2, 0.0))
        need = np.maximum(need, np.where(c, np.maximum(lack, 0.0), 0.0))
    if need.max() > 0:
        r = max(1, int(round(0.05 * fps)))
        for a, b in segments:
            if need[a:b].max() > 0:
                need[a:b] = gaussian_filter1d(maximum_filter1d(need[a:b], 4 * r + 1), r, mode="nearest")
        root[:, 1] -= need
        P = P - need[:, None, None] * np.array([0.0, 1.0, 0.0])

    contacts4 = np.zeros((N, 4), bool)
    for side, (c, Gdes, A_goal) in enumerate(legs):
        hip, knee, ankle, toe = LEG[side]
        near, dist = _nearest_contact(c, first, last)
        x = np.clip(dist / nb, 0, 1)
        w = np.where(c, 1.0, np.where(np.isfinite(dist), 1.0 - x * x * (3 - 2 * x), 0.0))
        floor = clearance[0] + (clearance[1] - clearance[0]) * np.clip((dist - 1) / nb, 0, 1)
        A = P[:, ankle] + (A_goal - P[:, ankle])[near] * w[:, None]
        A[c] = A_goal[c]
        arrays = [P[:, hip], P[:, knee], A, G[0], G[hip], R[knee], R[ankle],
                  offsets[knee], offsets[ankle], offsets[toe], Gdes[..., near], w]
        rots, A_new, toe_pos = _solve_leg(*arrays)
        # a foot gliding over the floor would look planted but slide: moving feet stay higher
        step = np.zeros(N)
        step[:-1] = np.maximum(np.linalg.norm(toe_pos[1:, [0, 2]] - toe_pos[:-1, [0, 2]], axis=-1),
                               np.linalg.norm(A_new[1:, [0, 2]] - A_new[:-1, [0, 2]], axis=-1))
        step[last] = 0.0
        moving = (step > 0.0015) | ((np.concatenate([[0.0], step[:-1]]) > 0.0015) & ~first)
        floor = np.where(moving, np.maximum(floor, 0.012), floor)
        # keep the swing foot above the floor: lift the ankle goal by any deficit and solve again
        # (a higher ankle bends the knee, which tips the toe down: a few rounds converge)
        lift = np.zeros(N)
        for _ in range(4):
            low = np.minimum(A_new[:, 1], toe_pos[:, 1])
            redo = ~c & (low < floor - 1e-6)
            if not redo.any():
                break
            lift[redo] += floor[redo] - low[redo]
            sub = [a[redo] if k in (0, 1, 2, 11) else a[..., redo] for k, a in enumerate(arrays)]
            sub[2] = sub[2] + lift[redo, None] * np.array([0.0, 1.0, 0.0])
            rots2, A2, toe2 = _solve_leg(*sub)
            for full, part in zip(rots, rots2):
                full[..., redo] = part
            A_new[redo], toe_pos[redo] = A2, toe2
        R[hip], R[knee], R[ankle] = rots
        contacts4[:, 2 * side + 1] = c & (foot_pitch[:, side] > -1e-6)
        contacts4[:, 2 * side] = c & (np.abs(foot_pitch[:, side]) < 1e-6)
    return R, root, contacts4, foot_pitch
