"""BVH motion files: a strict, non-recursive reader, an atomic writer and a short summary.

A BVH file is a joint tree (HIERARCHY) followed by one row of channel values per frame (MOTION).
Conventions (see rotations.py and skeleton.py):
- a joint's rotation channels compose intrinsically in the listed order, angles in degrees:
  "Zrotation Yrotation Xrotation" gives R = Rz · Ry · Rx (rotation order "ZYX");
- a joint's local translation is its OFFSET, except along axes that have a position channel, where
  the channel value is used instead (so the root's, or any 6-channel joint's, translation is data);
- End Sites are not joints; their offsets are kept in `BVHMotion.end_sites` for writing.
Every problem with a file raises `BVHError` (a ValueError) whose message starts with the file name.
"""
from __future__ import annotations

import os
import re
import tempfile
import warnings
from dataclasses import dataclass, field
from itertools import chain
from pathlib import Path

import numpy as np

from . import rotations as rot
from .skeleton import Skeleton, forward_kinematics

AXES = "XYZ"
CHANNEL_NAMES = tuple(f"{a}{kind}" for kind in ("position", "rotation") for a in AXES)
_CANONICAL = {c.lower(): c for c in CHANNEL_NAMES}
_STRUCTURE = {"{", "}", "JOINT", "END", "OFFSET", "CHANNELS", "ROOT", "HIERARCHY"}
_FLOAT_RE = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_INT_RE = re.compile(r"[+-]?[0-9]+")
_TOKEN_RE = re.compile(r"[{}]|[^\s{}]+")
_MOTION_RE = re.compile(r"^[ \t]*MOTION[ \t]*$", re.MULTILINE | re.IGNORECASE)


class BVHError(ValueError):
    """A malformed BVH file or an inconsistent BVH motion."""


def rotation_order(channels) -> str:
    """The Euler order of a channel list: its rotation axes in order, then the missing ones (XYZ)."""
    present = [c[0] for c in channels if c.endswith("rotation")]
    return "".join(present + [a for a in AXES if a not in present])


@dataclass(eq=False)
class BVHMotion:
    """A BVH clip: skeleton, channel layout, local rotations (T, J, 3, 3) and translations (T, J, 3)."""

    skeleton: Skeleton
    channels: list
    rotation_orders: list
    local_rotations: np.ndarray = field(repr=False)
    positions: np.ndarray = field(repr=False)
    fps: float
    end_sites: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        J, names = self.skeleton.n_joints, self.skeleton.names
        self.local_rotations = np.asarray(self.local_rotations, dtype=np.float64)
        self.positions = np.asarray(self.positions, dtype=np.float64)
        self.channels = [list(c) for c in self.channels]
        self.rotation_orders = [str(o) for o in self.rotation_orders]
        self.end_sites = {int(j): np.asarray(o, np.float64).reshape(3) for j, o in self.end_sites.items()}
        self.fps = float(self.fps)
        T = self.local_rotations.shape[0] if self.local_rotations.ndim == 4 else -1
        problems = []
        if self.local_rotations.shape != (T, J, 3, 3) or self.positions.shape != (T, J, 3):
            problems.append(f"local_rotations {self.local_rotations.shape} and positions "
                            f"{self.positions.shape} do not fit (T, {J}, 3, 3) and (T, {J}, 3)")
        if len(self.channels) != J or len(self.rotation_orders) != J:
            problems.append(f"need one channel list and one rotation order per joint ({J})")
        problems += [f"joint {name!r}: invalid channels {chans} or rotation order {order!r}"
                     for name, chans, order in zip(names, self.channels, self.rotation_orders)
                     if set(chans) - set(CHANNEL_NAMES) or len(set(chans)) != len(chans)
                     or order != rotation_order(chans)]
        if any(not 0 <= j < J for j in self.end_sites):
            problems.append(f"end_sites refer to joints outside 0..{J - 1}")
        if not (np.isfinite(self.fps) and self.fps > 0):
            problems.append(f"fps must be finite and > 0, got {self.fps}")
        if not (np.isfinite(self.local_rotations).all() and np.isfinite(self.positions).all()):
            problems.append("local_rotations and positions must be finite")
        if problems:
            raise BVHError("BVHMotion: " + "; ".join(problems))

    n_frames = property(lambda self: self.local_rotations.shape[0], doc="Number of frames T.")
    n_joints = property(lambda self: self.skeleton.n_joints, doc="Number of joints J.")
    frame_time = property(lambda self: 1.0 / self.fps, doc="Seconds per frame.")
    root_positions = property(lambda self: self.positions[:, 0], doc="Root translation per frame, (T, 3).")

    def global_positions(self) -> np.ndarray:
        """World joint positions (T, J, 3) by forward kinematics with the per-frame translations."""
        return forward_kinematics(self.skeleton, self.local_rotations, self.root_positions,
                                  offsets=self.positions)

    @classmethod
    def from_arrays(cls, skeleton: Skeleton, local_rotations, root_positions, fps,
                    rotation_order: str = "ZYX", end_sites=None) -> "BVHMotion":
        """A motion with a 6-channel root and 3 rotation channels elsewhere; rotations are (T, J, 3, 3)
        matrices or (T, J, 4) quaternions, end_sites maps joint index or name → offset."""
        given, root = _as_array(local_rotations), _as_array(root_positions)
        R = rot.quat_to_matrix(given) if given.shape[-1:] == (4,) else given
        J = skeleton.n_joints
        if R.ndim != 4 or R.shape[1:] != (J, 3, 3) or root.shape != (R.shape[0], 3):
            raise BVHError(f"from_arrays: expected local_rotations (T, {J}, 3, 3) or (T, {J}, 4) and "
                           f"root_positions (T, 3), got {given.shape} and {root.shape}")
        order = str(rotation_order).upper()
        if sorted(order) != list(AXES):
            raise BVHError(f"from_arrays: rotation_order must permute XYZ, got {rotation_order!r}")
        rot_channels = [f"{a}rotation" for a in order]
        channels = [[f"{a}position" for a in AXES] + rot_channels] + [rot_channels] * (J - 1)
        positions = np.repeat(skeleton.offsets[None], R.shape[0], axis=0)
        positions[:, 0] = root
        sites = {(skeleton.index(k) if isinstance(k, str) else k): v for k, v in (end_sites or {}).items()}
        return cls(skeleton, channels, [order] * J, R, positions, fps, sites)


def _as_array(x) -> np.ndarray:
    return np.asarray(x.detach().cpu() if hasattr(x, "detach") else x, dtype=np.float64)


def _channel_layout(channels):
    """Column bookkeeping: each joint's first column, the total, (joint, axis, column) rows of the
    position channels, and per rotation order the joints and their angle columns (-1: no channel)."""
    starts, pos, groups, col = [], [], {}, 0
    for j, chans in enumerate(channels):
        starts.append(col)
        order, angle_cols = rotation_order(chans), [-1, -1, -1]
        for k, c in enumerate(chans):
            if c.endswith("position"):
                pos.append((j, AXES.index(c[0]), col + k))
            else:
                angle_cols[order.index(c[0])] = col + k
        if max(angle_cols) >= 0:
            joints, cols = groups.setdefault(order, ([], []))
            joints.append(j), cols.append(angle_cols)
        col += len(chans)
    groups = {o: (np.array(js), np.array(cs)) for o, (js, cs) in groups.items()}
    return starts, col, np.array(pos, dtype=np.int64).reshape(-1, 3), groups


def euler_degrees_to_matrix(angles: np.ndarray, order: str) -> np.ndarray:
    """(..., 3) intrinsic Euler angles in degrees → (..., 3, 3); the same result as
    rotations.euler_to_matrix(angles, order, degrees=True), several times faster (quaternion products)."""
    half = np.deg2rad(np.asarray(angles, dtype=np.float64)) / 2
    q = None
    for k, axis in enumerate(order):
        qk = np.zeros(half.shape[:-1] + (4,))
        qk[..., 0], qk[..., 1 + AXES.index(axis)] = np.cos(half[..., k]), np.sin(half[..., k])
        q = qk if q is None else rot.quat_mul(q, qk)
    return rot.quat_to_matrix(q)


# ---------------------------------------------------------------- reading
class _Parser:
    """Iterative (non-recursive) parser over the tokens of the HIERARCHY part."""

    def __init__(self, hierarchy: str, source: str):
        self.source, self.i = source, 0
        self.tokens = [(tok, n) for n, line in enumerate(hierarchy.split("\n"), 1)
                       for tok in _TOKEN_RE.findall(line)]

    def error(self, msg, line=None):
        return BVHError(f"{self.source}: " + (f"line {line}: " if line is not None else "") + msg)

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else (None, None)

    def take(self, what):
        if self.i >= len(self.tokens):
            last = self.tokens[-1][1] if self.tokens else None
            raise self.error(f"the hierarchy ends before {what} (truncated, or unbalanced braces)", last)
        self.i += 1
        return self.tokens[self.i - 1]

    def expect(self, word, what):
        tok, line = self.take(what)
        if tok.upper() != word.upper():
            raise self.error(f"expected {what}, found {tok!r}", line)

    def offset(self, owner):
        toks = [self.take(f"OFFSET value {k + 1} of 3 for {owner}") for k in range(3)]
        return [_parse_float(t, f"OFFSET value of {owner}", lambda m: self.error(m, n)) for t, n in toks]

    def channels(self, owner, line):
        tok, _ = self.take(f"the channel count of {owner}")
        n, names = _small_int(tok), []
        if n is None or n > 6:
            raise self.error(f"CHANNELS of {owner}: the count must be an integer 0..6, got {tok!r}", line)
        while len(names) < n:
            name, name_line = self.peek()
            if name is None or name.upper() in _STRUCTURE:
                raise self.error(f"wrong channel count: CHANNELS {n} of {owner} lists only {len(names)}", line)
            if name.lower() not in _CANONICAL:
                raise self.error(f"unknown channel name {name!r} in {owner} "
                                 f"(known: {', '.join(CHANNEL_NAMES)})", name_line)
            names.append(_CANONICAL[name.lower()])
            self.i += 1
        if (self.peek()[0] or "").lower() in _CANONICAL:
            raise self.error(f"wrong channel count: CHANNELS {n} of {owner} lists more than {n} names", line)
        if len(set(names)) != n:
            raise self.error(f"duplicate channel in CHANNELS of {owner}: {names}", line)
        return names

    def parse(self):
        """Joint names, parents, offsets (J, 3), channel lists and End Sites of the hierarchy."""
        if not self.tokens or self.tokens[0][0].upper() != "HIERARCHY":
            raise self.error("missing HIERARCHY keyword at the start of the file")
        tok, line = self.tokens[1] if len(self.tokens) > 1 else (None, None)
        if tok is None or tok.upper() != "ROOT":
            raise self.error("zero joints: HIERARCHY declares no ROOT joint" if tok is None
                             else f"expected ROOT after HIERARCHY, found {tok!r}", line)
        names, parents, offsets, channels, sites, where, has_children, stack = [], [], [], [], {}, {}, [], []

        def open_joint(keyword, line, parent):
            parts = []
            while self.peek()[1] == line and self.peek()[0] not in ("{", "}"):
                parts.append(self.take("a joint name")[0])
            name = " ".join(parts)
            if not name:
                raise self.error(f"{keyword} without a joint name", line)
            if name in where:
                raise self.error(f"duplicate joint name {name!r} (first defined at line {where[name]})", line)
            self.expect("{", f"'{{' after {keyword} {name}")
            where[name] = line
            names.append(name), parents.append(parent), offsets.append(None)
            channels.append(None), has_children.append(False), stack.append(len(names) - 1)

        self.i = 2
        open_joint("ROOT", line, -1)
        while stack:
            j = stack[-1]
            owner = f"joint {names[j]!r}"
            if self.i >= len(self.tokens):
                raise self.error(f"unbalanced braces: the block of {owner} (line {where[names[j]]}) "
                                 "is never closed before MOTION")
            tok, line = self.take("'}'")
            up = tok.upper()
            if up in ("OFFSET", "CHANNELS"):
                store = offsets if up == "OFFSET" else channels
                if store[j] is not None or has_children[j]:  # data columns follow CHANNELS order
                    raise self.error(f"{up} of {owner} repeated or placed after its children", line)
                store[j] = self.offset(owner) if up == "OFFSET" else self.channels(owner, line)
            elif up in ("JOINT", "END"):
                if offsets[j] is None:
                    raise self.error(f"{owner} has no OFFSET before its children", line)
                has_children[j] = True
                if up == "JOINT":
                    open_joint("JOINT", line, j)
                    continue
                self.expect("Site", "'Site' after 'End'")
                if j in sites:
                    raise self.error(f"{owner} has more than one End Site", line)
                self.expect("{", "'{' after End Site")
                self.expect("OFFSET", f"OFFSET in the End Site of {owner}")
                sites[j] = self.offset(f"the End Site of {owner}")
                self.expect("}", f"'}}' closing the End Site of {owner}")
            elif tok == "}":
                if offsets[j] is None:
                    raise self.error(f"{owner} has no OFFSET", line)
                channels[j] = channels[j] or []
                stack.pop()
            else:
                raise self.error(f"unbalanced braces: unexpected '{{' inside {owner}" if tok == "{" else
                                 f"unexpected {tok!r} inside {owner} (expected OFFSET, CHANNELS, JOINT, "
                                 "End Site or '}')", line)
        tok, line = self.peek()
        if tok is not None:
            raise self.error("unbalanced braces: '}' after the root joint is closed" if tok == "}" else
                             f"unexpected {tok!r} after the root joint (only one ROOT is supported)", line)
        return names, parents, np.array(offsets, dtype=np.float64), channels, sites


def _small_int(tok):
    """tok as a non-negative int, or None if it is not one (or absurdly long)."""
    return int(tok) if len(tok) <= 15 and _INT_RE.fullmatch(tok) and int(tok) >= 0 else None


def _parse_float(tok, what, error):
    if not _FLOAT_RE.fullmatch(tok):
        raise error(f"non-numeric {what}: {tok!r}")
    value = float(tok)
    if not np.isfinite(value):
        raise error(f"{what} is not finite: {tok!r}")
    return value


def _header_value(lines, k, first_line, pattern, label, source):
    """The value after `label` on the next non-blank motion line, its line number and the next index."""
    while k < len(lines) and not lines[k].strip():
        k += 1
    m = re.fullmatch(pattern, lines[k].strip(), re.IGNORECASE) if k < len(lines) else None
    if m is None:
        found = f"found {lines[k].strip()[:40]!r}" if k < len(lines) else "the file ends"
        raise BVHError(f"{source}: line {first_line + k}: missing '{label}' line after MOTION ({found})")
    return m.group(1), first_line + k, k + 1


def _parse_motion(lines, first_line: int, n_channels: int, source: str):
    """Frame count, frame time and (T, C) data of the MOTION block (lines[0] is the MOTION line)."""
    tok, line, k = _header_value(lines, 1, first_line, r"Frames\s*:\s*(.*)", "Frames:", source)
    n_frames = _small_int(tok)
    if n_frames is None:
        raise BVHError(f"{source}: line {line}: the frame count must be an integer >= 0, got 'Frames: {tok}'")
    tok, line, k = _header_value(lines, k, first_line, r"Frame\s+Time\s*:\s*(.*)", "Frame Time:", source)
    frame_time = _parse_float(tok, "Frame Time", lambda m: BVHError(f"{source}: line {line}: {m}"))
    if not (frame_time > 0 and np.isfinite(1.0 / frame_time)):
        raise BVHError(f"{source}: line {line}: Frame Time must be > 0 with a finite 1/Frame Time, got {tok}")
    rows = [(first_line + n, line.split()) for n, line in enumerate(lines[k:], k) if line.strip()]
    for f, (n, row) in enumerate(rows):
        if len(row) != n_channels:
            raise BVHError(f"{source}: line {n} (frame {f + 1}): expected {n_channels} values, got {len(row)}"
                           + (" (truncated motion block?)" if f == len(rows) - 1 else ""))
    if len(rows) != n_frames:
        kind = "truncated motion block" if len(rows) < n_frames else "more rows than declared"
        raise BVHError(f"{source}: frame count mismatch: 'Frames: {n_frames}' but {len(rows)} rows ({kind})")
    flat = list(chain.from_iterable(row for _, row in rows))
    lenient = not all(s.isascii() and "_" not in s for s in lines[k:])  # float() would accept these
    try:
        data = np.array(flat, dtype=np.float64).reshape(n_frames, n_channels)
    except ValueError:
        data = None
    if lenient or data is None or not np.isfinite(data).all():  # find and report the first bad value
        for f, (n, row) in enumerate(rows):
            for c, tok in enumerate(row):
                _parse_float(tok, f"value (frame {f + 1}, channel {c + 1})",
                             lambda m: BVHError(f"{source}: line {n}: {m}"))
    return n_frames, frame_time, data


def parse_bvh_text(text, source: str = "<string>") -> BVHMotion:
    """Parse BVH text (str, or bytes decoded as UTF-8) into a BVHMotion; problems raise BVHError."""
    if isinstance(text, (bytes, bytearray, memoryview)):
        try:
            text = bytes(text).decode("utf-8-sig")
        except UnicodeDecodeError as e:
            raise BVHError(f"{source}: not UTF-8 text ({e.reason} at byte {e.start})") from None
    if not isinstance(text, str):
        raise TypeError(f"parse_bvh_text expects str or bytes, got {type(text).__name__}")
    try:
        return _parse(text.lstrip("\ufeff"), source)
    except MemoryError:
        raise
    except Exception as e:  # safety net for the "only ValueError" contract; the fuzz test looks for it
        if isinstance(e, BVHError) and str(e).startswith(f"{source}: "):
            raise
        raise BVHError(f"{source}: internal error while parsing: {type(e).__name__}: {e}") from e


def _parse(text: str, source: str) -> BVHMotion:
    if not text.strip():
        raise BVHError(f"{source}: the file is empty")
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    m = _MOTION_RE.search(text)
    if m is None:
        raise BVHError(f"{source}: missing MOTION section (a line containing only 'MOTION')")
    names, parents, offsets, channels, sites = _Parser(text[:m.start()], source).parse()
    _, n_channels, pos, groups = _channel_layout(channels)
    motion_line = text.count("\n", 0, m.start()) + 1
    n_frames, frame_time, data = _parse_motion(text[m.start():].split("\n"), motion_line, n_channels, source)
    skeleton = Skeleton(tuple(names), tuple(parents), offsets)
    positions = np.repeat(offsets[None], n_frames, axis=0)
    positions[:, pos[:, 0], pos[:, 1]] = data[:, pos[:, 2]]
    local = np.tile(np.eye(3), (n_frames, len(names), 1, 1))
    for order, (joints, cols) in groups.items():
        angles = np.where(cols >= 0, data[:, np.maximum(cols, 0)], 0.0)  # (T, k, 3)
        local[:, joints] = euler_degrees_to_matrix(angles, order)
    orders = [rotation_order(c) for c in channels]
    return BVHMotion(skeleton, channels, orders, local, positions, 1.0 / frame_time, sites)


def read_bvh(path) -> BVHMotion:
    """Read a BVH file; every problem (an unreadable file included) raises BVHError naming it."""
    try:
        raw = Path(path).read_bytes()
    except OSError as e:
        raise BVHError(f"{path}: cannot read the file ({e.strerror or e})") from None
    return parse_bvh_text(raw, source=str(path))


# ---------------------------------------------------------------- writing
def channel_data(motion: BVHMotion) -> np.ndarray:
    """The (T, C) channel values (rotations in degrees) in the joint order of `motion.channels`;
    angles about axes without a rotation channel are dropped."""
    _, n_channels, pos, groups = _channel_layout(motion.channels)
    data = np.zeros((motion.n_frames, n_channels))
    data[:, pos[:, 2]] = motion.positions[:, pos[:, 0], pos[:, 1]]
    if motion.n_frames:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy warns on gimbal lock; the matrix is still exact
            for order, (joints, cols) in groups.items():
                euler = rot.matrix_to_euler(motion.local_rotations[:, joints], order, degrees=True)
                # with the last axis unused, take the twin solution (a0+180, 180-a1, a2+180) if a2 is ~±180
                twin = (np.abs(euler[..., 2]) > 90) & (cols[:, 2] < 0)
                alt = (euler * [1, -1, 1] + 180 + 180) % 360 - 180
                euler = np.where(twin[..., None], alt, euler)
                data[:, cols[cols >= 0]] = euler[:, cols >= 0]
    return data


def format_bvh(motion: BVHMotion, precision: int = 6) -> str:
    """The BVH text of a motion; joints are written depth-first (the order a reader gets back)."""
    if not 0 <= int(precision) <= 17:
        raise BVHError(f"format_bvh: precision must be 0..17, got {precision}")
    sk, fmt = motion.skeleton, f"%.{int(precision)}f"
    bad = [n for n in sk.names if not isinstance(n, str) or n != " ".join(n.split()) or not n or set(n) & set("{}")]
    if bad:
        raise BVHError(f"format_bvh: joint names {bad} cannot be written (empty, braces or odd whitespace)")
    children, depth = [[] for _ in sk.names], [0] * sk.n_joints
    for j, p in enumerate(sk.parents[1:], 1):
        children[p].append(j)
        depth[j] = depth[p] + 1
    out, stack, order = ["HIERARCHY"], [(0, False)], []
    while stack:
        j, closing = stack.pop()
        ind = "\t" * depth[j]
        if closing:
            if j in motion.end_sites:
                out += [f"{ind}\tEnd Site", f"{ind}\t{{",
                        f"{ind}\t\tOFFSET " + " ".join(fmt % x for x in motion.end_sites[j]), f"{ind}\t}}"]
            out.append(f"{ind}}}")
            continue
        order.append(j)
        out += [f"{ind}{'ROOT' if j == 0 else 'JOINT'} {sk.names[j]}", f"{ind}{{",
                f"{ind}\tOFFSET " + " ".join(fmt % x for x in sk.offsets[j]),
                f"{ind}\t" + " ".join(["CHANNELS", str(len(motion.channels[j]))] + motion.channels[j])]
        stack += [(j, True)] + [(c, False) for c in reversed(children[j])]
    starts = _channel_layout(motion.channels)[0]
    columns = [starts[j] + k for j in order for k in range(len(motion.channels[j]))]
    data = channel_data(motion)[:, columns]
    out += ["MOTION", f"Frames: {motion.n_frames}", f"Frame Time: {motion.frame_time:.10g}"]
    row_fmt = " ".join([fmt] * data.shape[1])
    out += [row_fmt % tuple(row) for row in data.tolist()]
    return "\n".join(out) + "\n"


def write_bvh(path, motion: BVHMotion, *, precision: int = 6, overwrite: bool = False) -> Path:
    """Write a motion atomically (a temp file in the same folder, then os.replace); returns the path."""
    path = Path(path)
    if path.exists() and (path.is_dir() or not overwrite):
        raise BVHError(f"{path}: " + ("is a directory" if path.is_dir() else
                                      "the file already exists (pass overwrite=True to replace it)"))
    if not path.parent.is_dir():
        raise BVHError(f"{path}: the folder {path.parent} does not exist")
    text = format_bvh(motion, precision)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        umask = os.umask(0o022)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file ordinary permissions
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def bvh_info(path) -> dict:
    """A JSON-able summary of a BVH file (the whole file is read and validated)."""
    m = read_bvh(path)
    counts = {name: len(c) for name, c in zip(m.skeleton.names, m.channels)}
    orders = sorted({o for o, c in zip(m.rotation_orders, m.channels)
                     if any(x.endswith("rotation") for x in c)})
    return {
        "file": str(path), "n_joints": m.n_joints, "joints": list(m.skeleton.names),
        "n_frames": m.n_frames, "fps": m.fps, "frame_time": m.frame_time,
        "duration_s": m.n_frames * m.frame_time, "channels_per_joint": counts,
        "total_channels": sum(counts.values()), "rotation_orders": orders, "n_end_sites": len(m.end_sites),
    }
