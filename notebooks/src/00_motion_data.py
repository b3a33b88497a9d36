# %% [markdown]
# # 00 · Motion data: the skeleton, the 263-d vector and the built-in stylized mocap
#
# Every paper in this workbook speaks **HumanML3D**: 22 joints in SMPL order, Y up, metres, 20 frames
# per second, and a 263-number vector per frame. This notebook builds that language from the ground
# up and then meets the data every later notebook uses: a procedural generator of stylized motion
# capture, with two corpora shaped like paper A's cross-dataset benchmark.
#
# **What you will learn**
# - the template skeleton and forward kinematics (local rotations → joint positions);
# - the 263-d vector block by block, and that `decode(encode(x))` gives the motion back;
# - the eight Xia styles and their sub-styles, foot contacts, and the corpora's sizes and splits;
# - what the benchmark's metrics say about two reference "methods" that do no style transfer at all.

# %%
import mslib
mslib.setup_notebook(seed=0)

import numpy as np
import matplotlib.pyplot as plt

from mslib import viz
from mslib.motion import skeleton as sk
from mslib.motion import rotations as rot
from mslib.motion import features as F
from mslib.data.synth import generate_clip
from mslib.data.styles import STYLES, SUBSTYLES, CONTENTS

# %% [markdown]
# ## 1. The template skeleton
# Each joint has a parent and a rest offset (its position relative to the parent when the body stands
# in the rest pose). The offsets carry the HumanML3D reference body's bone lengths.

# %%
for j in (0, 1, 4, 7, 10, 9, 12, 15, 16, 18, 20):
    parent = sk.PARENTS[j]
    print(f"{j:>2} {sk.JOINT_NAMES[j]:<14} parent {parent:>2}  offset {np.round(sk.HUMANML3D.offsets[j], 4)}")

# %% [markdown]
# **Forward kinematics**: a joint's global rotation is its parent's times its own local rotation, and
# its position is the parent's position plus the parent's global rotation applied to its offset:
# $G_j = G_{p(j)} R_j$, $\;p_j = p_{p(j)} + G_{p(j)}\, o_j$. Bend the left hip forward and the left
# knee back, and the whole leg follows.

# %%
R = np.broadcast_to(np.eye(3), (22, 3, 3)).copy()
R[1] = rot.axis_angle_to_matrix(np.array([-0.9, 0, 0]))   # left hip: thigh forward (about −X)
R[4] = rot.axis_angle_to_matrix(np.array([1.2, 0, 0]))    # left knee: shin back
pose = sk.forward_kinematics(sk.HUMANML3D, R, np.array([0, 0.95, 0]))
rest = sk.forward_kinematics(sk.HUMANML3D, np.broadcast_to(np.eye(3), (22, 3, 3)), np.array([0, 0.95, 0]))
fig, axes = plt.subplots(1, 2, figsize=(6, 3))
viz.plot_pose(axes[0], rest, view="side", title="rest pose")
viz.plot_pose(axes[1], pose, view="side", title="left hip and knee bent")
fig.tight_layout()
print("bone lengths kept:", np.allclose(sk.positions_bone_lengths(pose, sk.PARENTS), sk.positions_bone_lengths(rest, sk.PARENTS)))
_ = fig

# %% [markdown]
# ## 2. The 263-d vector, block by block
# `encode` turns T frames of positions into T − 1 rows (velocities need the next frame):

# %%
clip = generate_clip("turn_walk", "neutral", seed=0, index=3)
feats = F.encode(clip.positions)
print("positions", clip.positions.shape, "→ features", feats.shape)
for name, sl in F.BLOCKS.items():
    print(f"  [{sl.start:>3}:{sl.stop:<3}] {name:<13} {sl.stop - sl.start:>3} numbers")

# %% [markdown]
# The root is described by *velocities* in its own facing frame — angular velocity about Y (half the
# yaw step, a quirk of the original code), forward/sideways speed and height — so a motion can be
# moved and turned freely. The last block marks the feet on the ground (a joint barely moving).

# %%
t = np.arange(len(feats)) / 20
fig, axes = plt.subplots(3, 1, figsize=(6, 4.5), sharex=True)
axes[0].plot(t, feats[:, 0]); axes[0].set_ylabel("yaw vel.\n(half-rad/frame)")
axes[1].plot(t, feats[:, 2], label="forward"); axes[1].plot(t, feats[:, 1], label="sideways")
axes[1].set_ylabel("root vel.\n(m/frame)"); axes[1].legend(fontsize=7)
axes[2].imshow(feats[:, 259:].T, aspect="auto", cmap="Greys", extent=[0, t[-1], 3.5, -0.5], interpolation="nearest")
axes[2].set_yticks(range(4), ["L ankle", "L toe", "R ankle", "R toe"]); axes[2].set_xlabel("time (s)")
axes[0].set_title("a turning walk: root block and foot contacts")
fig.tight_layout()
_ = fig

# %% [markdown]
# **Round trip.** `decode` integrates the root's rotation and velocity and adds back the
# root-relative joints. On built-in clips of every content it reproduces the positions (the last
# frame has no row):

# %%
worst = 0.0
for i, content in enumerate(CONTENTS):
    c = generate_clip(content, "neutral", seed=0, index=i)
    back = F.decode(F.encode(c.positions).astype(np.float64))
    worst = max(worst, float(np.abs(back - c.positions[:-1]).max()))
print(f"decode(encode(x)) over {len(CONTENTS)} contents: max error {worst * 1000:.2f} mm")

# %% [markdown]
# ## 3. Eight styles
# The generator drives joint angles with a gait phase; each style is a distribution over posture
# (spine and head pitch, shoulders), amplitude (arm swing, stride, knee lift), tempo (cadence) and
# dynamics (bounce, sway, tremor), with means fitted to real motion capture (§6). The root is then
# moved so that the stance foot stays planted.

# %%
walks = [generate_clip("walk", s, seed=0, index=10 + i, duration=3.0) for i, s in enumerate(STYLES)]
fig = viz.plot_strip([w.positions for w in walks], n_frames=5, view="side", titles=list(STYLES))
_ = fig

# %% [markdown]
# In the 3-D viewer below, drag to turn the skeletons, scroll to zoom, and play, pause or scrub; feet light up while
# they touch the floor. (Without a running kernel, a still picture stands in for it.)

# %%
# NBVAL_IGNORE_OUTPUT
viz.MotionViewer([w.positions for w in walks[:4]], titles=list(STYLES[:4]))

# %% [markdown]
# Each style has named **sub-styles** — the intra-style diversity paper D models with prototypes:

# %%
style = "old"
subs = SUBSTYLES[style]
clips = [generate_clip("walk", style, sub, seed=0, index=40 + i, duration=3.0) for i, sub in enumerate(subs)]
print(style, "sub-styles:", subs)
_ = viz.plot_strip([c.positions for c in clips], n_frames=5, view="side", titles=[f"{style} · {s}" for s in subs])

# %% [markdown]
# ## 4. Trajectories and foot contacts
# Physical plausibility is built in: a foot in contact does not slide, the lowest foot point touches
# the floor, bone lengths never change.

# %%
paths = [generate_clip(c, "neutral", seed=2, index=i, duration=4.0) for i, c in enumerate(("walk", "turn_walk", "side_step", "run"))]
_ = viz.plot_trajectory([p.positions for p in paths], labels=["walk", "turn_walk", "side_step", "run"], contacts="auto")
from mslib.data.synth import plausibility
for p, name in zip(paths, ("walk", "turn_walk", "side_step", "run")):
    check = plausibility(p.positions, p.contacts, p.fps)
    print(f"{name:<10} planted-foot slide {1000 * check['max_contact_slide']:.2f} mm/frame (≤ 2), "
          f"lowest foot point {abs(100 * check['min_foot_height']):.2f} cm (≤ 1), "
          f"bones constant: {check['bone_length_spread'] < 1e-5}, fastest joint {check['max_joint_speed']:.1f} m/s (≤ 12)")

# %% [markdown]
# ## 5. The two corpora (paper A's cross-dataset benchmark)
# - **content corpus**: HumanML3D-like, 20 fps, every content, mild random style, captions;
# - **style corpus**: eight styles × five Xia contents, recorded as BVH takes on another skeleton at
#   30 fps, registered onto the template (notebook 01) and cut into 32-frame windows.
#
# Both are built once and cached on disk.

# %%
from mslib.data.corpora import load_builtin
from mslib.data.dataset_folder import read_labels, read_meta
from collections import Counter

paths = load_builtin(seed=0, progress=False)
for name in ("content", "style"):
    meta = read_meta(paths[name])
    rows = read_labels(paths[name])
    print(f"{name:>7} corpus: {meta['n_clips']} clips, splits {meta['splits']}")
content_rows = read_labels(paths["content"])
style_rows = read_labels(paths["style"])
print("contents:", dict(sorted(Counter(r["content"] for r in content_rows).items())))
print("styles (style corpus):", dict(sorted(Counter(r["style"] for r in style_rows).items())))
print("a caption from each:", content_rows[0]["caption"], "|", style_rows[0]["caption"])

# %% [markdown]
# ## 6. How real is the built-in data?
# A generator can make any motion it likes; what matters is whether its styles look like real ones.
# The yardstick is real motion capture: Xia et al.'s (2015) stylized walks, runs, jumps, punches and
# kicks — one actor, the same eight styles — registered onto the template body as in notebook 01.
# Those takes are not part of the workbook (a research licence), but what was measured on them is:
#
# - the generator's numbers are **fitted** to the Xia *train* takes (`tools/fit_styles.py`, stored in
#   `mslib/data/fitted_styles.json`): the trunk's rest geometry, and every style's posture, arm
#   carriage and swing, stride, knee lift, cadence, bounce, sway and tempo, so that its motions are
#   described like the real style's — by the cues below and by where they fall among the real styles.
#   The three sub-styles of each style are thirds of its real walks, split along the axis on which
#   they differ most. Each style's runs, jumps, punches and kicks are then fitted on their own, where
#   the real takes have them: an actor's action need not keep the tempo of the same actor's walk.
#   Jumps are planned alike for every style: real jumps of every style take about as long and rise
#   about as high, with the pelvis tipping forward in the crouch, the legs tucked in flight and the arms
#   swung high, so the style of a built-in jump lies in its posture and in the layer below.
#   Last, a per-joint layer (`tools/fit_joint_moments.py`) gives every style × content cell its own
#   posture offset, amplitude gain and small 0.5–2 Hz motion per joint angle, fitted so that the cell's
#   windows fall where the real ones do — along the directions in which the real styles differ, along
#   those in which the built-in styles differ (where a judge trained on built-in data looks), and in
#   every feature's mean, the mean pose above all (what a network trained on built-in clips reads
#   most: the bounds at the end of this section) — and, for walks, so that the walking cues match too;
# - the **realism report** then checks the result on held-out Xia *test* takes:
#
#       python -m mslib data realism --real XIA_TRAIN_DIR --grid XIA_GRID_DIR --out notebooks/data/00_realism.json
#
# It describes a walking window by a dozen **cues**, in leg lengths L (so a tall and a short actor
# compare) and per second:
#
# | group | cues |
# |---|---|
# | posture | head height, trunk pitch (degrees), head ahead of the pelvis, shoulders above the neck |
# | amplitude | arm swing (wrists' forward spread), stride, knee lift, hands' sideways spread |
# | tempo | cadence (steps/s), walking speed |
# | dynamics | vertical bounce and lateral sway of the pelvis, jerk (third derivative) |
#
# and asks two **cross** questions: does a classifier trained on real takes only (a logistic
# regression on the means and spreads of 16-frame windows) recognise the built-in styles (*real →
# built-in*)? A real punch take holds one punch and is often shorter than that window, so the judge
# reads a take of 8 to 15 frames whole, as one window: otherwise it would never see a neutral punch.
# And does the packaged style evaluator, trained on built-in data only, recognise the real ones
# (*built-in → real*)? The last lines ask that again of the real judge's own recipe, fitted on built-in
# windows instead: where it reads real takes better than the evaluator does, the evaluator's network is part
# of the gap; what it still misses is the data's.
# Each panel below is one cue: real (●) against built-in (■) per style, ± one spread over windows.

# %%
from mslib.notebook import load_findings
from mslib.evaluation.realism import format_cross_scores, realism_figure

realism = load_findings("00_realism")  # written by `python -m mslib data realism`
_ = realism_figure(realism, dpi=100)

# %%
print(format_cross_scores(realism))

# %% [markdown]
# Read the figure style by style: the real old walker stoops (trunk pitch, head ahead) and so does the
# built-in one; the real proud walker swings his arms widest, and so does the built-in one. The cross
# scores are the hard test. The judge trained on real takes now reads most built-in windows as their
# own style: the walks and runs about as often as it reads real test windows right, the jumps, punches
# and kicks less often (the *by content* line). The built-in test split holds only a take or two of each
# style, sub-style and content, so which takes it holds moves its figure by several points; the line for
# the built-in *train* windows reads several times as many takes (none of them chose anything in the
# generator) and is the steadier figure. Those cells were fitted to a handful of real windows
# each, and the per-joint layer can only match where a style's windows fall on average, not how the
# cues move together within a punch. That match has a price the panels show: the per-joint layer aimed
# at where windows fall among the real styles, not at these cues, and every built-in walker is now
# jerkier than its real counterpart (the jerk panel), the old one taking shorter and slower steps than the
# real old walker (stride, speed). The other direction has nearly caught up: the evaluator trained on
# built-in clips alone recognises most real test takes — every old and strutting one — but misses more of
# the neutral, angry and proud takes than of the rest. The linear recipe fitted on built-in windows (the last
# lines) reads no more real takes than the evaluator does: the gap is not the evaluator's network but the
# data. The per-joint layer matches the cells' mean *poses* as well as the judges'
# directions, and a network trained on built-in clips reads poses first (the bounds below). Yet the
# evaluator still misreads some real takes: a classifier trained on
# built-in clips alone still learns cues of the generator that real takes do not share. That is why the
# benchmark of notebook 07 judges real pairs twice: once by the packaged evaluator, once by a judge trained
# on real takes.

# Could the evaluator instead be taught to ignore the generator's quirks? A search in `tools/`
# (`evaluator_augment.py`) trained it on windows mirrored left to right, replayed faster or slower, or with
# noise added — and, in case the network merely overfits the generator, with weight decay, more dropout, a
# narrower net or a slower learning rate — two seeds each, and scored every candidate on the real *train* takes only (the grid is
# never used to choose). A candidate is adopted only if it beats no augmentation by more than two seeds of
# one recipe differ from each other:

# %%
augment = load_findings("00_evaluator_augment")  # written by `python tools/evaluator_augment.py`
plain, best = augment["summary"]["none"], augment["summary"][augment["chosen"]]
print(f"real train takes recognised: no augmentation {plain['real_train_takes']:.1f} %, "
      f"best candidate ({augment['chosen']}) {best['real_train_takes']:.1f} %; "
      f"widest gap between two seeds {augment['spread']:.1f} points → {'adopted' if augment['adopted'] else 'not adopted'}")

# %% [markdown]
# None cleared that bar: what the packaged evaluator cannot read in real takes is not a matter of mirror
# images, tempo, noise or overfitting, but of how the built-in styles themselves still differ from the real ones.
#
# How far could a better-fitted built-in corpus go? Another diagnosis in `tools/` (`realism_gap.py`) asks it
# of the linear recipe: it trains the judge on built-in windows as generated, then on the same windows with
# every (style, content) cell moved to the real cell's mean, then to its mean and spread (x' = μ_real +
# (x − μ_built)·σ_real/σ_built, feature by feature), the real cells measured on one half of the real train
# takes, and reads the other half; a judge trained on that first half of the real takes is the ceiling. It
# then asks the packaged evaluator's own recipe the same, moving each cell's frames (the network's input: root
# height and root-relative joints) to the real cell's mean pose, then to its mean and spread:

# %%
reverse = load_findings("00_realism_gap")["reverse"]  # written by `python tools/realism_gap.py`
for judge, rows in (("linear judge", reverse["rows"]), ("evaluator's network", reverse["network"]["rows"])):
    for part, label in (("takes", "all held-out real takes"), ("other takes", "their jumps, runs, punches, kicks")):
        print(f"{judge}, {label}, trained on: " + ", ".join(f"{row['judge trained on']} {row[part]:.1f} %"
                                                           for row in rows))

# %% [markdown]
# Moving the cells' means alone does not help the linear judge — it reads a few fewer real takes than when
# trained on the corpus as generated — but matching the spreads too lifts it above the corpus as generated; even
# so, a linear judge trained on such a corpus stays below one trained on real takes. The evaluator's network
# gains more: it reads poses, and moving the mean poses already helps it a little where the built-in actions are furthest
# from the real ones (the jumps, runs, punches and kicks). A built-in corpus whose styles held each action in the
# real mean pose, and scattered about it as widely, would train it to recognise more real takes, though still
# fewer than a linear judge trained on real takes does. What numbers per cell
# cannot carry — how a style moves within a take, the timing and shape of a punch or a jump — is the rest.

# %% [markdown]
# ## 7. How the benchmark will measure style transfer
# Every method in notebooks 02–07 turns a (content clip, style clip) pair into a new motion. An
# **independent evaluator** — two small temporal conv nets trained once on labelled built-in data
# (content classes from the content corpus, the eight styles from the style corpus), never seen by
# any method — scores the outputs:
#
# | metric | what it asks | better |
# |---|---|---|
# | CRA (%) | does the content classifier still recognise the content motion's action? | ↑ |
# | SRA (%) | does the style classifier see the style motion's style? (top-3 too) | ↑ |
# | H | harmonic mean 2·SRA·CRA/(SRA+CRA): only good when both are | ↑ |
# | FMD | Fréchet distance between evaluator features of outputs and of real style clips | ↓ |
# | TSI (m) | mean distance between the output's and the content's root paths | ↓ |
# | FSF (cm/frame) | horizontal foot slide while a foot is near the floor (natural motion is not 0) | ↓ |
# | FSR | fraction of frames where a grounded foot skates faster than 0.5 m/s | ↓ |
# | diversity | mean feature distance between random output pairs | — |
#
# Two reference "methods" calibrate it: **identity** returns the content motion unchanged (perfect
# content, no style) and **copy_style** returns the style motion looped to the content's length (all
# style, no content). Each gets half of the task right, so both have a low H — every real method
# must beat both.

# %%
from mslib.evaluation.bench import Evaluator, format_table, load_pairs, run_bench

evaluator = Evaluator()            # the packaged course checkpoints (python -m mslib train evaluator_…)
pairs = load_pairs(seed=0, n_pairs=100)
rows = [run_bench(m, pairs=pairs, evaluator=evaluator) for m in ("identity", "copy_style")]
print(format_table(rows, notebook=True))

# %%
fig, ax = plt.subplots(figsize=(5, 2.6))
for k, r in enumerate(rows):
    ax.bar([k - 0.2], [r["cra"]], width=0.4, color="tab:blue", label="CRA" if k == 0 else None)
    ax.bar([k + 0.2], [r["sra"]], width=0.4, color="tab:orange", label="SRA" if k == 0 else None)
ax.set_xticks(range(len(rows)), [r["method"] for r in rows])
ax.set(ylabel="accuracy (%)", ylim=(0, 105), title="each reference row gets half of the task right")
ax.legend()
_ = fig

# %% [markdown]
# ## Exercises
# **Exercise 1 (2 points) — the root, integrated.** The 263-d vector stores the root as velocities in its own
# facing frame (§2). Write `integrate_root(f)` for features (T, 263) that returns the root's positions (T, 3):
# the heading angle $a_0 = 0$, $a_t = \sum_{s<t} f_{s,0}$ (the half-yaw steps); the step in the facing frame
# $(v_x, v_z) = (f_{t-1,1}, f_{t-1,2})$ turned to the world, $x = v_x\cos 2a_t - v_z\sin 2a_t$,
# $z = v_x\sin 2a_t + v_z\cos 2a_t$ (no step at $t = 0$); the positions are the running sums of those steps, and
# the height is $f_{t,3}$. A hidden test tries other clips.

# %% [nbgrader solution id=ex00_integrate_root]
def integrate_root(f):
    """Root positions (T, 3) from the root block of features (T, 263): heading, turned steps, running sums."""
    ### BEGIN SOLUTION
    a = np.concatenate([[0.0], np.cumsum(f[:-1, 0])])                      # heading a_t
    vx, vz = np.concatenate([[0.0], f[:-1, 1]]), np.concatenate([[0.0], f[:-1, 2]])
    x = np.cumsum(vx * np.cos(2 * a) - vz * np.sin(2 * a))
    z = np.cumsum(vx * np.sin(2 * a) + vz * np.cos(2 * a))
    return np.stack([x, f[:, 3], z], -1)
    ### END SOLUTION

# %% [nbgrader tests id=ex00_integrate_root_check points=2]
f_turn = F.encode(generate_clip("turn_walk", "neutral", seed=0, index=3).positions).astype(np.float64)
assert integrate_root(f_turn).shape == (len(f_turn), 3), "one root position per feature row"
assert np.allclose(integrate_root(f_turn), F.recover_root(f_turn)[1], atol=1e-9), "compare with F.recover_root(f)[1]"
### BEGIN HIDDEN TESTS
for content, idx in (("walk", 7), ("run", 2)):
    f_ = F.encode(generate_clip(content, "old", seed=1, index=idx).positions).astype(np.float64)
    assert np.allclose(integrate_root(f_), F.recover_root(f_)[1], atol=1e-9)
### END HIDDEN TESTS
print("integrate_root matches recover_root")

# %% [markdown]
# **Exercise 2 (1 point) — predict, then run.** *Predict* first: does the built-in **old** walk take steps more
# or less often than the **neutral** one (its cadence, steps per second)? Write `prediction = "more"` or
# `"less"`. Then measure `cadence[s]` for s in ("neutral", "old") with `cues(w.positions)["cadence"]` (from
# `mslib.evaluation.cues`) on §3's walks (`walks[STYLES.index(s)]`). The hidden test grades the prediction
# against your measurement.

# %% [nbgrader solution id=ex00_predict_cadence]
from mslib.evaluation.cues import cues
### BEGIN SOLUTION
prediction = "less"
cadence = {s: cues(walks[STYLES.index(s)].positions)["cadence"] for s in ("neutral", "old")}
### END SOLUTION

# %% [nbgrader tests id=ex00_predict_cadence_check points=1]
assert prediction in ("more", "less"), "prediction: 'more' or 'less'"
assert set(cadence) == {"neutral", "old"} and all(v > 0 for v in cadence.values()), "cadence: steps per second of each walk"
### BEGIN HIDDEN TESTS
ref = {s: cues(walks[STYLES.index(s)].positions)["cadence"] for s in ("neutral", "old")}
assert all(abs(cadence[s] - ref[s]) < 1e-9 for s in ref)
assert prediction == ("more" if ref["old"] > ref["neutral"] else "less")
### END HIDDEN TESTS
print("checked")
