# %% [markdown]
# # 01 · Cross-dataset registration: any BVH → the HumanML3D body
#
# Paper A (§3.1, §4.1) transfers style *across datasets*: content comes from HumanML3D, style from a
# motion-capture set recorded on another skeleton, at another frame rate, in other units. Before any
# network sees them, both must live on **one body in one frame of reference**. This notebook walks
# through that registration step by step on the workbook's built-in style corpus, whose takes are BVH
# files on a 32-joint "mocap" skeleton in centimetres at 30 fps.
#
# **What you will learn**
# - how a joint map picks the 22 template joints out of another skeleton (by name, and by the tree's
#   structure where names are ambiguous);
# - the preprocessing order of HumanML3D: resample → rescale to the reference body → floor →
#   origin → facing +Z (→ mirror), then 32-frame windows with 8-frame overlap (A §4.1);
# - how to check that nothing was lost: the registered motion against the generator's ground truth.

# %%
import mslib
mslib.setup_notebook(seed=0)

import numpy as np
import matplotlib.pyplot as plt
from IPython.display import HTML

from mslib import viz
from mslib.data import retarget as R
from mslib.data import joint_maps as JM
from mslib.data.corpora import load_builtin
from mslib.motion import skeleton as sk
from mslib.motion.bvh import read_bvh, bvh_info
from mslib.motion.features import decode, foot_contacts

paths = load_builtin(seed=0, progress=False)  # built once (≈30 s), then cached on disk
take_files = sorted(paths["style_bvh"].glob("*.bvh"))
print(len(take_files), "BVH takes in the built-in style corpus")

# %% [markdown]
# ## 1. A raw take: another skeleton
# `bvh_info` summarises the file. The mocap skeleton has more joints than the template (hip joints,
# a lower back, a second neck joint, toe ends, fingers), other names, a T-pose rest and centimetres.

# %%
walk_file = next(f for f in take_files if f.stem.endswith("old_walk"))
info = bvh_info(walk_file)
print({"n_joints": info["n_joints"], "n_frames": info["n_frames"], "fps": round(info["fps"], 2),
       "rotation_orders": info["rotation_orders"]})
raw = read_bvh(walk_file)
print("first joints:", raw.skeleton.names[:8])

# %%
fig, axes = plt.subplots(1, 2, figsize=(7, 3.2))
viz.plot_pose(axes[0], raw.skeleton.rest_positions() / 100, parents=raw.skeleton.parents,
              names=raw.skeleton.names, view="front", title="mocap rest pose (T-pose, cm → m)")
viz.plot_pose(axes[1], sk.HUMANML3D.rest_positions(), view="front", title="HumanML3D template rest pose")
fig.tight_layout()
_ = fig

# %% [markdown]
# ## 2. The joint map
# `auto` reads names (Left/Right/L/R markers; UpLeg, Arm, ForeArm, …) and falls back on the tree:
# the knee is the ankle's parent, the upper spine is where the arms branch, and spine1/spine2 are
# the joints whose height along the spine matches the template's. Here it agrees with the named
# `builtin` dialect.

# %%
auto = JM.auto_joint_map(raw.skeleton)
named = JM.resolve_joint_map(raw.skeleton, "builtin")
print("auto == builtin dialect:", auto == named)
for t in ("pelvis", "spine1", "spine2", "spine3", "neck", "left_collar", "left_shoulder", "left_foot"):
    print(f"  {t:>13} ← {auto[t]}")

# %% [markdown]
# ## 3. Step by step
# **Resample** 30 → 20 fps: local rotations are interpolated by slerp (never Euler angles), the root
# translation linearly.

# %%
at20 = R.resample(raw, 20)
print(f"{raw.n_frames} frames at {raw.fps:.0f} fps → {at20.n_frames} frames at {at20.fps:.0f} fps")
hand = raw.skeleton.index("LeftHand")
fig, ax = plt.subplots(figsize=(6, 2.4))
ax.plot(np.arange(raw.n_frames) / raw.fps, raw.global_positions()[:, hand, 1] / 100, ".", ms=3, label="30 fps")
ax.plot(np.arange(at20.n_frames) / at20.fps, at20.global_positions()[:, hand, 1] / 100, "o", ms=3, mfc="none", label="20 fps")
ax.set(xlabel="time (s)", ylabel="left hand height (m)", title="resampling keeps the curve")
ax.legend()
_ = fig

# %% [markdown]
# **Pick and rescale.** The 22 mapped joints are taken from the source's world positions; then every
# bone keeps its direction but gets the reference body's length, and the root path is scaled by the
# leg-length ratio — what HumanML3D's inverse kinematics on the source followed by forward
# kinematics with the template offsets amounts to. Units disappear on the way (cm → m).

# %%
picked = R.select_template_joints(at20.global_positions(), raw.skeleton, auto)
rescaled = R.rescale_to_reference(picked)
bones_before = sk.positions_bone_lengths(picked, sk.PARENTS)[0, 1:]
bones_after = sk.positions_bone_lengths(rescaled, sk.PARENTS)[0, 1:]
print("leg length before (source units):", round(R.leg_length(picked), 2))
print("max |bone − reference| after (m):", float(np.abs(bones_after - sk.REFERENCE_BONE_LENGTHS).max().round(6)))

# %% [markdown]
# **Floor, origin, facing +Z.** The lowest point of the clip goes to y = 0, frame 0's root to the
# origin, and the whole take is turned so that its initial facing — `cross(up, across)` with
# `across` = right − left hips and shoulders — points along +Z.

# %%
canonical = R.canonicalize(rescaled)
fig = viz.plot_trajectory([rescaled - rescaled[:1, :1] * [1, 0, 1], canonical],
                          labels=["before (world heading)", "after (faces +Z)"], contacts="auto")
print("initial facing after:", R.facing_direction(canonical[0]).round(3) + 0.0)
_ = fig

# %% [markdown]
# **Mirror** (augmentation): negate X and swap left and right joints. Mirroring twice is the identity.

# %%
mirrored = R.canonicalize(sk.mirror_positions(canonical))
back = R.canonicalize(sk.mirror_positions(mirrored))
print("mirror twice, max error (m):", float(np.abs(back - canonical).max().round(8)))
_ = viz.plot_strip([canonical, mirrored], n_frames=5, view="front", titles=["registered", "mirrored"])

# %% [markdown]
# **Windows** (A §4.1): the style corpus is cut into 32-frame windows overlapping by 8 frames; each
# window is re-centred and re-faced, and keeps the take's floor.

# %%
starts = R.window_starts(len(canonical))
print(f"{len(canonical)} frames → windows starting at {starts}")
fig, ax = plt.subplots(figsize=(6, 1.6))
for k, s in enumerate(starts):
    ax.barh(k % 2, R.WINDOW, left=s, height=0.8, alpha=0.6)
ax.set(xlabel="frame", yticks=[], title="32-frame windows, 8-frame overlap")
_ = fig

# %% [markdown]
# ## 4. The whole pipeline in one call, and the 263-d vector
# `register_bvh` runs all of the above and encodes the HumanML3D vector. Decoding that vector gives
# the positions back.

# %%
reg = R.register_bvh(walk_file, dialect="auto")
print(reg.info["fps"], reg.info["up"], reg.positions.shape, reg.features.shape)
print("decode(features) vs positions, max error (m):",
      float(np.abs(decode(reg.features.astype(np.float64)) - reg.positions[:-1]).max().round(5)))

# %%
# NBVAL_IGNORE_OUTPUT
HTML(viz.animation_html([reg.positions], titles=["registered old walk"], max_frames=40))

# %% [markdown]
# ## 5. Did registration lose anything?
# The generator knows the true template motion of every take. We register each of 16 takes from its
# BVH file and compare with that ground truth (rescaled to the reference body, as registration does):
# the mean joint error after aligning the roots (MPJPE) and how often the foot contacts agree.

# %%
from mslib.data.synth import generate_clip, resample as resample_clip
from mslib.data.mocap_skeleton import to_bvh_motion
from mslib.data.styles import STYLES

errors, agree = [], []
for i, (content, style) in enumerate([(c, s) for c in ("walk", "punch") for s in STYLES]):
    take = generate_clip(content, style, seed=1, index=i, fps=30.0, canonical=False)
    registered = R.register_motion(to_bvh_motion(take.rotations, take.root, take.skeleton), "auto").positions
    truth = R.canonicalize(R.rescale_to_reference(resample_clip(take, 20).positions))
    n = min(len(truth), len(registered))
    a, b = registered[:n] - registered[:n, :1], truth[:n] - truth[:n, :1]
    errors.append(np.linalg.norm(a - b, axis=-1).mean())
    agree.append((foot_contacts(registered[:n]) == foot_contacts(truth[:n])).mean())
print(f"MPJPE over 16 takes: mean {100 * np.mean(errors):.2f} cm, max {100 * np.max(errors):.2f} cm")
print(f"foot contacts agree on {100 * np.mean(agree):.1f}% of frames (worst take {100 * np.min(agree):.1f}%)")

# %% [markdown]
# ## Exercises
# **Exercise 1 (2 points) — facing +Z.** The last step of registration turns a take so that its first frame
# faces +Z. Write `face_plus_z(p)` for positions (T, 22, 3), Y up: move frame 0's root (joint 0) to the origin in
# X and Z; find frame 0's forward direction, $\text{up} \times \text{across}$ with across $=$ (right hip − left
# hip) + (right shoulder − left shoulder) (joints 2 − 1 and 17 − 16), projected on the floor; then turn every
# frame about Y by the angle that takes forward to +Z. (A turn by θ about Y maps $(x, z)$ to
# $(x\cos\theta + z\sin\theta,\; -x\sin\theta + z\cos\theta)$, and forward $(f_x, f_z)$ has heading
# $\mathrm{atan2}(f_x, f_z)$.) A hidden test tries other takes.

# %% [nbgrader solution id=ex01_face_plus_z]
def face_plus_z(p):
    """Positions (T, 22, 3) moved so frame 0's root is at X = Z = 0 and turned so frame 0 faces +Z."""
    ### BEGIN SOLUTION
    q = np.array(p, dtype=np.float64)
    q[..., [0, 2]] -= q[0, 0, [0, 2]]
    across = (q[0, 2] - q[0, 1]) + (q[0, 17] - q[0, 16])
    forward = np.cross([0.0, 1.0, 0.0], across)
    theta = -np.arctan2(forward[0], forward[2])                            # turn the heading back to 0
    x, z = q[..., 0].copy(), q[..., 2].copy()
    q[..., 0], q[..., 2] = x * np.cos(theta) + z * np.sin(theta), -x * np.sin(theta) + z * np.cos(theta)
    return q
    ### END SOLUTION

# %% [nbgrader tests id=ex01_face_plus_z_check points=2]
turned = canonical @ np.array([[0.6, 0, -0.8], [0, 1, 0], [0.8, 0, 0.6]]).T + [1.0, 0, 2.0]  # §3's take, turned and moved
mine = face_plus_z(turned)
assert np.allclose(mine, R.canonicalize(turned, floor=False), atol=1e-9), "compare with R.canonicalize(p, floor=False)"
assert np.allclose(R.facing_direction(mine[0]), [0, 0, 1], atol=1e-9), "frame 0 must face +Z"
### BEGIN HIDDEN TESTS
for angle in (2.5, -1.2):
    c_, s_ = np.cos(angle), np.sin(angle)
    t_ = canonical @ np.array([[c_, 0, s_], [0, 1, 0], [-s_, 0, c_]]).T + [-0.5, 0.1, 3.0]
    assert np.allclose(face_plus_z(t_), R.canonicalize(t_, floor=False), atol=1e-9)
### END HIDDEN TESTS
print("face_plus_z matches canonicalize")

# %% [markdown]
# **Exercise 2 (1 point) — predict, then run.** A skeleton from another studio names its joints `Bip01_L_Thigh`,
# `Bip01_L_Calf`, … (below, with the template's tree). *Predict* first, from the names and the tree alone: which
# of its joints will `JM.auto_joint_map` choose as the template's `left_knee`? Write it in `prediction`. Then run
# the map and store its choice in `chosen`. The hidden test grades the prediction.

# %%
biped_names = ["Bip01_Pelvis", "Bip01_L_Thigh", "Bip01_R_Thigh", "Bip01_Spine", "Bip01_L_Calf",
               "Bip01_R_Calf", "Bip01_Spine1", "Bip01_L_Foot", "Bip01_R_Foot", "Bip01_Spine2",
               "Bip01_L_Toe0", "Bip01_R_Toe0", "Bip01_Neck", "Bip01_L_Clavicle", "Bip01_R_Clavicle",
               "Bip01_Head", "Bip01_L_UpperArm", "Bip01_R_UpperArm", "Bip01_L_Forearm", "Bip01_R_Forearm",
               "Bip01_L_Hand", "Bip01_R_Hand"]
biped = sk.Skeleton(tuple(biped_names), sk.PARENTS, sk.HUMANML3D.offsets)

# %% [nbgrader solution id=ex01_predict_knee]
### BEGIN SOLUTION
prediction = "Bip01_L_Calf"
chosen = JM.auto_joint_map(biped)["left_knee"]
### END SOLUTION

# %% [nbgrader tests id=ex01_predict_knee_check points=1]
assert prediction in biped_names, "prediction: one of biped_names"
assert chosen == JM.auto_joint_map(biped)["left_knee"], "chosen: what auto_joint_map picks for left_knee"
### BEGIN HIDDEN TESTS
assert prediction == "Bip01_L_Calf"
### END HIDDEN TESTS
print("checked: the map chose", chosen)
