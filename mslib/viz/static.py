"""Static pictures of motions (matplotlib): stick figures, strips, trajectories, animations, loss curves.

Motions are arrays (T, J, 3) in metres, Y up, the character facing +Z with its left at +X.
Views (each a real camera, never a mirror image):
  front  camera at +Z looking at the face: screen right = +X, the character's left on your right;
  side   camera at the character's right (−X): screen right = +Z, so forward motion goes left→right;
  top    camera above: screen up = +Z (forward), screen right = −X (the X axis runs right→left);
  3d     a 3/4 view from the front-left (mpl axes x = X, y = −Z shown as Z, z = Y).
Colours: the character's left side blue, its right side red, the spine dark grey.
Only `mslib.motion` is imported from the library (layers import downward only).
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, MaxNLocator

from ..motion.skeleton import JOINT_NAMES, KINEMATIC_CHAINS, PARENTS

SIDE_COLOURS = {"left": "#1f77b4", "right": "#d62728", "centre": "#3a3a3a"}
SIDE_LABELS = {"left": "left side", "right": "right side", "centre": "spine"}
PATH_COLOURS = ("#222222", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#bcbd22")
_TEMPLATE_SIDES = ("right", "left", "centre", "right", "left")
# view → (screen-horizontal axis, screen-vertical axis, horizontal axis inverted, depth axis,
#         +1 if a larger depth coordinate is nearer the camera)
VIEWS_2D = {"front": (0, 1, False, 2, 1), "side": (2, 1, False, 0, -1), "top": (0, 2, True, 1, 1)}
_LABELS = {"front": ("X (m), the character's left →", "Y (m)"),
           "side": ("Z (m), forward →", "Y (m)"),
           "top": ("X (m), ← the character's left", "Z (m), forward →")}
_VIEW_NAMES = {"front": "front view", "side": "side view (from its right)", "top": "top view",
               "3d": "3-D view"}
DPI = 100


# ---------------------------------------------------------------- validation
def _as_array(x, name: str) -> np.ndarray:
    """A float numpy array from an array-like or a torch tensor."""
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: cannot be read as a numeric array ({e})") from None


def _check_finite(a: np.ndarray, name: str):
    bad = ~np.isfinite(a)
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{name}: contains NaN or Inf values (first at index {where})")


def _check_positions(x, name: str, n_joints: int | None, ndim: int) -> np.ndarray:
    """Validate one pose (J, 3) when ndim=2 or one motion (T, J, 3) when ndim=3."""
    a = _as_array(x, name)
    shape = "(J, 3)" if ndim == 2 else "(T, J, 3)"
    if a.ndim != ndim:
        raise ValueError(f"{name}: expected an array of shape {shape}, got shape {a.shape}")
    if a.shape[-1] != 3:
        raise ValueError(f"{name}: the last axis must hold (x, y, z) (size 3), got shape {a.shape}")
    if ndim == 3 and a.shape[0] < 1:
        raise ValueError(f"{name}: needs at least 1 frame, got shape {a.shape}")
    if a.shape[-2] < 1:
        raise ValueError(f"{name}: needs at least 1 joint, got shape {a.shape}")
    if n_joints is not None and a.shape[-2] != n_joints:
        raise ValueError(f"{name}: has {a.shape[-2]} joints but the skeleton (parents) has "
                         f"{n_joints}")
    _check_finite(a, name)
    return a


def _motion_list(motions, name: str, n_joints: int | None) -> list[np.ndarray]:
    """One motion (T, J, 3) or a list of them → a list of validated arrays."""
    if isinstance(motions, (list, tuple)):
        if len(motions) == 0:
            raise ValueError(f"{name}: the list of motions is empty")
        return [_check_positions(m, f"{name}[{i}]", n_joints, 3) for i, m in enumerate(motions)]
    return [_check_positions(motions, name, n_joints, 3)]


def _check_labels(labels, n: int, name: str):
    if labels is None:
        return None
    if isinstance(labels, str):
        labels = [labels]
    labels = list(labels)
    if len(labels) != n:
        raise ValueError(f"{name}: {len(labels)} given for {n} motion(s)")
    return [str(t) for t in labels]


def _check_view(view: str, allowed) -> str:
    if view not in allowed:
        raise ValueError(f"view: must be one of {sorted(allowed)}, got {view!r}")
    return view


# ---------------------------------------------------------------- skeleton → coloured chains
def _side_of_name(name: str) -> str:
    """'left', 'right' or 'centre' from a joint name (left_hip, LeftUpLeg, LHipJoint, hand_l …)."""
    n = str(name)
    for side, word, letter in (("left", "left", "L"), ("right", "right", "R")):
        if (word in n.lower() or re.match(rf"^{letter}(?=[A-Z_.\d])", n)
                or re.match(rf"^{letter.lower()}_", n) or re.search(rf"[_.\s]{letter}$", n, re.I)):
            return side
    return "centre"


def skeleton_chains(parents=PARENTS, names=None):
    """(parents, chains, sides): bone chains to draw and the side of each (left, right, centre)."""
    if hasattr(parents, "parents"):  # a Skeleton
        names = parents.names if names is None else names
        parents = parents.parents
    try:
        parents = tuple(int(p) for p in parents)
    except (TypeError, ValueError):
        raise ValueError("parents: expected a sequence of parent indices or a Skeleton") from None
    if len(parents) == 0 or parents[0] != -1 or any(not 0 <= p < j for j, p in
                                                     enumerate(parents) if j):
        raise ValueError("parents: the root must be joint 0 (parent -1) and each parent must come "
                         f"before its child, got {parents}")
    if names is not None and len(names) != len(parents):
        raise ValueError(f"names: {len(names)} names for {len(parents)} joints")
    if parents == PARENTS and (names is None or tuple(names) == JOINT_NAMES):
        return parents, [tuple(c) for c in KINEMATIC_CHAINS], list(_TEMPLATE_SIDES)
    n_children = np.bincount([p for p in parents if p >= 0], minlength=len(parents))
    chains, tail_of = [], {}
    for j, p in enumerate(parents):
        if p < 0:
            continue
        if p in tail_of and n_children[p] == 1:
            chain = tail_of.pop(p)
            chain.append(j)
        else:
            chain = [p, j]
            chains.append(chain)
        tail_of[j] = chain
    sides = [_side_of_name(names[c[1]]) if names is not None else "centre" for c in chains]
    return parents, [tuple(c) for c in chains], sides


# ---------------------------------------------------------------- drawing helpers
def _new_figure(w: float, h: float, dpi: int = DPI) -> Figure:
    return plt.figure(figsize=(w, h), dpi=dpi)


def _side_handles(sides):
    """Legend proxies (not drawn in any axes) for the sides present, left/right/spine order."""
    return [Line2D([], [], color=SIDE_COLOURS[k], lw=2, label=SIDE_LABELS[k])
            for k in ("left", "right", "centre") if k in set(sides)]


def _coords(pos, c, view, shift=0.0):
    """Plot coordinates of joints c: (horizontal, vertical) in a 2-D view, (X, −Z, Y) in 3-D."""
    if view == "3d":
        return pos[c, 0], -pos[c, 2], pos[c, 1]
    hi, vi, inv = VIEWS_2D[view][:3]
    return pos[c, hi] + (-shift if inv else shift), pos[c, vi]


def _draw_pose(ax, pos, chains, sides, view, shift=0.0, lw=2.0):
    """Draw one pose as coloured chains (in 2-D nearer chains on top); returns the lines."""
    lines = []
    for c, side in zip(chains, sides):
        c = list(c)
        z = {}
        if view != "3d":                               # depth order: nearer → higher zorder
            di, near = VIEWS_2D[view][3:]
            z["zorder"] = 3 + math.atan(near * float(pos[c, di].mean()))
        lines += ax.plot(*_coords(pos, c, view, shift), "-o", color=SIDE_COLOURS[side], lw=lw,
                         ms=2.5, solid_capstyle="round", gid="bone", **z)
    return lines


def _update_pose(lines, pos, chains, view):
    for ln, c in zip(lines, chains):
        xyz = _coords(pos, list(c), view)
        ln.set_data_3d(*xyz) if view == "3d" else ln.set_data(*xyz)


def _limits(lo, hi, pad=0.1, min_size=0.5):
    """(low, high) padded and widened to at least min_size."""
    mid, half = (lo + hi) / 2, max((hi - lo) / 2 + pad, min_size / 2)
    return mid - half, mid + half


def _style_2d(ax, view, hlim, vlim, floor=True, xlabel=None):
    hi, vi, inv = VIEWS_2D[view][:3]
    if floor and vi == 1:
        ax.axhline(0.0, color="0.6", lw=0.8, zorder=1, gid="floor")
    ax.set_xlim(*(hlim[::-1] if inv else hlim))
    ax.set_ylim(*vlim)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(_LABELS[view][0] if xlabel is None else xlabel, fontsize=8)
    ax.set_ylabel(_LABELS[view][1], fontsize=8)
    ax.tick_params(labelsize=7)


def _style_3d(ax, pts):
    """Equal-scale 3-D limits around points (N, 3) with the floor at the bottom."""
    lo, hi = pts.min(0), pts.max(0)
    half = max(float((hi - lo).max()) / 2 + 0.1, 0.5)
    cx, cz = (lo[0] + hi[0]) / 2, (lo[2] + hi[2]) / 2
    y0 = min(float(lo[1]), 0.0) - 0.05
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(-cz - half, -cz + half)
    ax.set_zlim(y0, y0 + 2 * half)
    ax.set_box_aspect((1, 1, 1), zoom=1.0)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(3))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{0.0 - v:g}"))
    ax.set_xlabel("X (m)", fontsize=7, labelpad=-8)
    ax.set_ylabel("Z (m)", fontsize=7, labelpad=-8)
    ax.set_zlabel("Y (m)", fontsize=7, labelpad=-8)
    ax.tick_params(labelsize=6, pad=-3)
    ax.view_init(elev=15, azim=-60)


# ---------------------------------------------------------------- public API
def plot_pose(ax, positions, parents=PARENTS, view: str = "front", title: str | None = None,
              names=None, floor: bool = True, legend: bool = True, lw: float = 2.0) -> Figure:
    """Stick figure of one frame (J, 3): view 'front', 'side', 'top' or '3d'; returns the Figure."""
    view = _check_view(view, set(VIEWS_2D) | {"3d"})
    parents, chains, sides = skeleton_chains(parents, names)
    pos = _check_positions(positions, "positions", len(parents), 2)
    if ax is None:
        fig = _new_figure(3.2, 3.4)
        ax = fig.add_subplot(projection="3d" if view == "3d" else None)
    elif (view == "3d") != (getattr(ax, "name", "") == "3d"):
        raise ValueError(f"ax: view={view!r} needs {'a 3-D' if view == '3d' else 'a 2-D'} axes")
    _draw_pose(ax, pos, chains, sides, view, lw=lw)
    if view == "3d":
        _style_3d(ax, pos)
    else:
        hi, vi = VIEWS_2D[view][:2]
        vlo = min(pos[:, vi].min(), 0.0) if floor and vi == 1 else pos[:, vi].min()
        hl, vl = _limits(pos[:, hi].min(), pos[:, hi].max()), _limits(vlo, pos[:, vi].max())
        size = max(hl[1] - hl[0], vl[1] - vl[0])       # square limits: legible in any view
        _style_2d(ax, view, _limits(*hl, 0.0, size), _limits(*vl, 0.0, size), floor)
    ax.set_title(title if title is not None else _VIEW_NAMES[view], fontsize=9)
    if legend:
        ax.legend(handles=_side_handles(sides), fontsize=6, loc="best", framealpha=0.7)
    return ax.figure


def plot_strip(motions, n_frames: int = 6, view: str = "side", titles=None, row_labels=None,
               parents=PARENTS, names=None, fps: float = 20, spacing: str = "travel", axes=None) -> Figure:
    """Rows of n_frames evenly spaced poses, one row per motion, spread out side by side (into `axes`, one
    per motion, when given: a strip inside a larger figure)."""
    view = _check_view(view, set(VIEWS_2D))
    if spacing not in ("travel", "fixed"):
        raise ValueError(f"spacing: must be 'travel' (add the root's travel) or 'fixed', "
                         f"got {spacing!r}")
    if int(n_frames) < 1:
        raise ValueError(f"n_frames: must be at least 1, got {n_frames}")
    parents, chains, sides = skeleton_chains(parents, names)
    ms = _motion_list(motions, "motions", len(parents))
    titles = _check_labels(titles, len(ms), "titles")
    row_labels = _check_labels(row_labels, len(ms), "row_labels")
    hi, vi, inv = VIEWS_2D[view][:3]
    sgn = -1.0 if inv else 1.0                        # data → screen-horizontal
    rows, width, back = [], 0.3, 0.0
    for m in ms:
        idx = np.unique(np.linspace(0, len(m) - 1, int(n_frames)).round().astype(int))
        rel = sgn * (m[idx, :, hi] - m[idx, :1, hi])   # each pose about its root, screen units
        width = max(width, float(rel.max() - rel.min()))
        root = sgn * m[idx, 0, hi]
        if spacing == "travel" and len(idx) > 1:
            back = max(back, float(-np.diff(root).min()))
        rows.append((m, idx, root))
    gap = width + 0.15 + back                          # poses never overlap
    shifts = [gap * np.arange(len(idx)) - (0.0 if spacing == "travel" else root - root[0])
              for _, idx, root in rows]
    scr = [sgn * m[idx, :, hi] + sh[:, None] for (m, idx, _), sh in zip(rows, shifts)]
    hlim = _limits(min(x.min() for x in scr), max(x.max() for x in scr))
    v_lo = min(min(float(m[idx, :, vi].min()) for m, idx, _ in rows), 0.0 if vi == 1 else np.inf)
    vlim = _limits(v_lo, max(float(m[idx, :, vi].max()) for m, idx, _ in rows))
    fig_w = float(np.clip(1.1 * max(len(idx) for _, idx, _ in rows) + 1.0, 3.5, 11.0))
    aspect = (vlim[1] - vlim[0]) / (hlim[1] - hlim[0])
    row_h = float(np.clip(0.85 * fig_w * aspect + 0.7, 1.4, 4))
    fig_w = min(fig_w, max(3.5, (row_h - 0.7) / 0.85 / aspect + 1.0))   # tall rows: no wide margins
    if axes is None:
        fig, axes = plt.subplots(len(ms), 1, figsize=(fig_w, row_h * len(ms) + 0.6), dpi=DPI, squeeze=False)
    else:
        axes = np.asarray(axes, dtype=object).reshape(-1, 1)
        if len(axes) != len(ms):
            raise ValueError(f"axes: one per motion needed, got {len(axes)} for {len(ms)} motions")
        fig = None
    for i, ((m, idx, root), sh) in enumerate(zip(rows, shifts)):
        ax = axes[i, 0]
        for k, t in enumerate(idx):
            _draw_pose(ax, m[t], chains, sides, view, shift=sh[k])
        _style_2d(ax, view, (-hlim[1], -hlim[0]) if inv else hlim, vlim, xlabel="time (s)")
        ax.set_xticks(sgn * (root + sh), [f"{t / fps:.2f}" for t in idx])
        name = titles[i] if titles else (f"motion {i}" if len(ms) > 1 else "motion")
        ax.set_title(f"{name} ({len(m)} frames)" if not titles else name, fontsize=9)
        if row_labels:
            ax.set_ylabel(f"{row_labels[i]}\nY (m)" if vi == 1 else row_labels[i], fontsize=8)
    if fig is None:
        return axes[0, 0].figure
    fig.suptitle(_VIEW_NAMES[view] + (", forward →" if view == "side" else ""), fontsize=9,
                 x=0.02, ha="left")
    fig.legend(handles=_side_handles(sides), loc="upper right", ncol=3, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    return fig


def auto_contacts(motion, foot_joints=(10, 11), fps: float = 20, height: float = 0.05,
                  speed: float = 0.6) -> np.ndarray:
    """Boolean (T, len(foot_joints)): joint below `height` m and moving slower than `speed` m/s."""
    m = _check_positions(motion, "motion", None, 3)
    if max(foot_joints) >= m.shape[1]:
        raise ValueError(f"foot_joints: {foot_joints} out of range for {m.shape[1]} joints")
    feet = m[:, list(foot_joints)]
    v = np.zeros(feet.shape[:2])
    if len(m) > 1:
        step = np.linalg.norm(np.diff(feet[..., [0, 2]], axis=0), axis=-1) * fps
        v = np.concatenate([step, step[-1:]], axis=0)
    return (feet[..., 1] < height) & (v < speed)


def _contact_points(m, c, name, foot_joints, fps):
    """[(side, points (N, 3))] of the foot positions on contact frames."""
    T = len(m)
    if isinstance(c, str):
        if c != "auto":
            raise ValueError(f"{name}: must be None, 'auto' or a boolean array, got {c!r}")
        c, joints = auto_contacts(m, foot_joints, fps), list(foot_joints)
    else:
        c = _as_array(c, name)
        if c.ndim != 2 or c.shape[1] not in (2, 4) or c.shape[0] not in (T, T - 1):
            raise ValueError(f"{name}: expected shape ({T}, 2) [left, right] or ({T}, 4) [left 7, "
                             f"left 10, right 8, right 11] (or {T - 1} rows), got {c.shape}")
        _check_finite(c, name)
        joints = list(foot_joints) if c.shape[1] == 2 else [7, 10, 8, 11]
        if max(joints) >= m.shape[1]:
            raise ValueError(f"{name}: contact joints {joints} out of range for "
                             f"{m.shape[1]} joints")
    c = c.astype(bool)
    return [("left" if k < len(joints) // 2 else "right", m[np.nonzero(c[:, k])[0], j])
            for k, j in enumerate(joints)]


def plot_trajectory(motions, labels=None, contacts=None, fps: float = 20,
                    title: str = "root path (top view)", foot_joints=(10, 11)) -> Figure:
    """Top view of each root path (X–Z, equal aspect) with its start and optional foot contacts."""
    ms = _motion_list(motions, "motions", None)
    labels = _check_labels(labels, len(ms), "labels")
    if contacts is None or isinstance(contacts, str):
        contacts = [contacts] * len(ms)
    elif len(ms) == 1 and not (isinstance(contacts, (list, tuple)) and len(contacts) == 1):
        contacts = [contacts]
    elif len(contacts) != len(ms):
        raise ValueError(f"contacts: {len(contacts)} given for {len(ms)} motion(s)")
    feet = [None if c is None else _contact_points(m, c, "contacts" if len(ms) == 1 else
                                                   f"contacts[{i}]", foot_joints, fps)
            for i, (m, c) in enumerate(zip(ms, contacts))]
    fig = _new_figure(4.2, 4.2)
    ax = fig.add_subplot()
    pts, legend_sides = [], set()
    for i, m in enumerate(ms):
        colour = PATH_COLOURS[i % len(PATH_COLOURS)]
        root = m[:, 0]
        label = labels[i] if labels else (f"motion {i}" if len(ms) > 1 else "root path")
        ax.plot(root[:, 0], root[:, 2], "-", color=colour, lw=1.8, label=label, gid="path")
        ax.plot(root[:1, 0], root[:1, 2], "o", ms=8, mfc="white", mec=colour, mew=2,
                label="start" if i == 0 else "_nolegend_", gid="start", zorder=5)
        ax.plot(root[-1:, 0], root[-1:, 2], "x", ms=7, color=colour, mew=2,
                label="end" if i == 0 else "_nolegend_", gid="end", zorder=5)
        pts.append(root)
        for side, p in feet[i] or []:
            label = f"{side} foot contact" if side not in legend_sides else "_nolegend_"
            legend_sides.add(side)
            ax.plot(p[:, 0], p[:, 2], "o", ls="none", ms=4, color=SIDE_COLOURS[side], alpha=0.5,
                    label=label, gid="contact")
            pts.append(p)
    allp = np.concatenate(pts)
    xl = _limits(allp[:, 0].min(), allp[:, 0].max(), 0.2, 1.0)
    zl = _limits(allp[:, 2].min(), allp[:, 2].max(), 0.2, 1.0)
    half = max(xl[1] - xl[0], zl[1] - zl[0]) / 2
    xm, zm = sum(xl) / 2, sum(zl) / 2
    ax.set_xlim(xm + half, xm - half)                 # seen from above: +X (its left) on the left
    ax.set_ylim(zm - half, zm + half)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(_LABELS["top"][0], fontsize=8)
    ax.set_ylabel(_LABELS["top"][1], fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=6, loc="best", framealpha=0.7)
    fig.tight_layout()
    return fig


def animate(motions, titles=None, fps: float = 20, max_frames: int = 60, view: str = "3d",
            dpi: int = 60, parents=PARENTS, names=None, panel_size: float = 2.6) -> FuncAnimation:
    """FuncAnimation of one or several motions side by side, subsampled to ≤ max_frames frames."""
    view = _check_view(view, set(VIEWS_2D) | {"3d"})
    if int(max_frames) < 1:
        raise ValueError(f"max_frames: must be at least 1, got {max_frames}")
    if not fps > 0:
        raise ValueError(f"fps: must be positive, got {fps}")
    parents, chains, sides = skeleton_chains(parents, names)
    ms = _motion_list(motions, "motions", len(parents))
    titles = _check_labels(titles, len(ms), "titles")
    t_max = max(len(m) for m in ms)
    step = math.ceil(t_max / int(max_frames))
    n_out = math.ceil(t_max / step)
    fig = _new_figure(panel_size * len(ms), panel_size + 0.35, dpi)
    big = np.max([np.ptp(m.reshape(-1, 3), axis=0) for m in ms], axis=0)
    all_lines = []
    for i, m in enumerate(ms):                         # one scale, each panel on its own motion
        ax = fig.add_subplot(1, len(ms), i + 1, projection="3d" if view == "3d" else None)
        flat = m.reshape(-1, 3)
        centre = (flat.min(0) + flat.max(0)) / 2
        box = np.stack([centre - big / 2, centre + big / 2])
        all_lines.append(_draw_pose(ax, m[0], chains, sides, view))
        if view == "3d":
            _style_3d(ax, np.concatenate([flat, box]))
        else:
            hi, vi = VIEWS_2D[view][:2]
            vlo = min(float(flat[:, 1].min()), 0.0) if vi == 1 else float(box[0, vi])
            _style_2d(ax, view, _limits(box[0, hi], box[1, hi]),
                      _limits(vlo, max(float(flat[:, vi].max()), vlo + big[vi])))
        ax.set_title(titles[i] if titles else (f"motion {i}" if len(ms) > 1 else _VIEW_NAMES[view]),
                     fontsize=8)
        for axis in (ax.xaxis, ax.yaxis) + ((ax.zaxis,) if view == "3d" else ()):
            axis.set_major_formatter("")               # no tick labels: much faster frames
    clock = fig.text(0.01, 0.97, "t = 0.00 s", fontsize=7, va="top")
    if view == "3d":
        fig.subplots_adjust(left=0.02, right=0.95, bottom=0.05, top=0.9, wspace=0.1)
    else:
        fig.tight_layout(rect=(0, 0, 1, 0.95))

    def update(k):
        for m, lines in zip(ms, all_lines):
            _update_pose(lines, m[min(k * step, len(m) - 1)], chains, view)
        clock.set_text(f"t = {k * step / fps:.2f} s")
        return [ln for lines in all_lines for ln in lines] + [clock]

    anim = FuncAnimation(fig, update, frames=n_out, interval=1000.0 * step / fps, blit=False)
    anim.n_frames = n_out
    plt.close(fig)                                      # shown by its HTML only, never statically
    return anim


class HTMLString(str):
    """A str whose notebook display is the HTML itself (and whose text repr stays short)."""

    def _repr_html_(self):
        return str(self)

    def __repr__(self):
        return f"<HTML animation, {len(self)} characters>"


def animation_html(motions, **kwargs) -> HTMLString:
    """`animate(motions, **kwargs)` as a self-contained JavaScript player (to_jshtml, no ffmpeg)."""
    anim = animate(motions, **kwargs)
    return HTMLString(anim.to_jshtml(default_mode="loop"))


def plot_curves(histories: dict, title: str = "training", xlabel: str = "step",
                ylabel: str = "loss", logy: bool = False) -> Figure:
    """One line per named history (e.g. losses per step); returns the Figure."""
    if not isinstance(histories, dict) or not histories:
        raise ValueError("histories: expected a non-empty dict {name: list of values}")
    curves = {}
    for name, values in histories.items():             # validate everything before drawing
        v = curves[name] = _as_array(values, f"histories[{name!r}]")
        if v.ndim != 1 or len(v) < 1:
            raise ValueError(f"histories[{name!r}]: expected a non-empty 1-D list, "
                             f"got shape {v.shape}")
        _check_finite(v, f"histories[{name!r}]")
        if logy and (v <= 0).any():
            raise ValueError(f"histories[{name!r}]: logy=True needs positive values")
    fig = _new_figure(4.5, 3.0)
    ax = fig.add_subplot()
    for name, v in curves.items():
        ax.plot(np.arange(len(v)), v, "-" if len(v) > 1 else "o", lw=1.5, label=str(name))
    if logy:
        ax.set_yscale("log")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def save_png(fig, path) -> Path:
    """Save a Figure as PNG (parent folders created); returns the path."""
    if not isinstance(fig, Figure):
        raise ValueError(f"fig: expected a matplotlib Figure, got {type(fig).__name__}")
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise ValueError(f"path: must end in .png, got {str(path)!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png", bbox_inches="tight")
    return path
