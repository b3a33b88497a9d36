# %% [markdown]
# # 02 · AdaIN style transfer with dual-path training (paper A, stage 1)
#
# Paper A transfers a style by *statistics*: a content motion is encoded into a feature map over
# time, a style motion into another, and Adaptive Instance Normalisation (AdaIN) gives the content's
# features the per-channel mean and spread of the style's. A decoder turns the result back into
# motion. Content comes from one dataset (HumanML3D-shaped), style from another (the retargeted mocap
# of notebook 01): a *cross-dataset* transfer (A §4.1).
#
# **What you will learn**
# - what AdaIN does to a feature map (A Eq. 2), and its mean-only and variance-only halves;
# - the two training paths — self-reconstruction and stylization — and their losses (A Eq. 3–5);
# - how a short training run behaves on train and validation (A Table 1);
# - one content in all eight styles, and where A's "dynamic" and "static" noise come from (A Fig. 2);
# - how the method scores on the benchmark against the two reference rows;
# - why the course model reads content and style with one encoder, measured against A's separate one.

# %%
import mslib
mslib.setup_notebook(seed=0)


import numpy as np
import torch
import matplotlib.pyplot as plt

from mslib import viz
from mslib.checkpoints import checkpoint_digest, course_path
from mslib.data.corpora import load_builtin
from mslib.data.datasets import ContentClips, StyleClips
from mslib.data.styles import STYLES
from mslib.models import adain as A
from mslib.models.common.layers import adain, channel_stats
from mslib.motion.features import decode
from mslib.training import TrainConfig

paths = load_builtin(progress=False)

# %% [markdown]
# ## 1. AdaIN on a toy feature map
# Take a feature map $x$ of shape (time × channels). Per channel, its mean $\mu(x)$ and standard
# deviation $\sigma(x)$ over time are the "statistics". AdaIN (A Eq. 2) whitens the content's channels
# and re-colours them with the style's:
#
# $$\mathrm{AdaIN}(C_c, C_s) = \sigma(C_s)\,\frac{C_c - \mu(C_c)}{\sigma(C_c)} + \mu(C_s).$$
#
# The *shape* of each channel over time (when it rises and falls) stays the content's; its level and
# amplitude become the style's. Switching off one half gives **mean-only** (shift, keep the content's
# spread) and **variance-only** (rescale, keep the content's level) transfer.

# %%
t = torch.linspace(0, 2 * np.pi, 60)
toy_content = torch.stack([torch.sin(t), 0.3 * torch.cos(2 * t) + 1.0], -1)[None]      # (1, 60, 2)
toy_style = torch.stack([0.2 * torch.sin(5 * t) - 1.5, 2.0 * torch.sin(t + 1)], -1)[None]  # (1, 60, 2)
mu_s, sig_s = channel_stats(toy_style)
variants = {"content": toy_content, "style": toy_style,
            "AdaIN (full)": adain(toy_content, mu_s, sig_s),
            "mean only": adain(toy_content, mu_s, sig_s, use_std=False),
            "variance only": adain(toy_content, mu_s, sig_s, use_mean=False)}
print(f"{'':<14} {'mu ch0':>7} {'mu ch1':>7} {'sigma ch0':>9} {'sigma ch1':>9}")
for name, x in variants.items():
    mu, sig = channel_stats(x)
    print(f"{name:<14} {mu[0, 0, 0]:>7.2f} {mu[0, 0, 1]:>7.2f} {sig[0, 0, 0]:>9.2f} {sig[0, 0, 1]:>9.2f}")
fig, axes = plt.subplots(1, 2, figsize=(9, 2.6), sharex=True)
for ch, ax in enumerate(axes):
    for name, x in variants.items():
        ax.plot(x[0, :, ch].numpy(), label=name, lw=2 if name.startswith("AdaIN") else 1,
                ls="--" if name in ("content", "style") else "-")
    ax.set_title(f"channel {ch}")
axes[1].legend(fontsize=7, loc="upper right")
fig.tight_layout()
_ = fig

# %% [markdown]
# The full transfer's statistics are exactly the style's; mean-only keeps the content's σ, and
# variance-only keeps the content's μ. The curve shapes are the content's in every case.
#
# ## 2. The model and its two training paths
# - **Content encoder** $E_c$: residual 1-D convolutions over the *normalised 263-d* features of the
#   content motion (A §4.1.1: rotations, root velocity and foot contacts describe content well).
# - **Style statistics**: A §3.2.1 uses a separate small transformer $E_s$ over the style motion's joint
#   positions. The course model instead reads the style motion with the **same** encoder, $C_s = E_c(P_s)$,
#   so AdaIN moves the statistics of the same channels it normalises — as in the image methods A builds
#   on (Gatys et al.; Huang & Belongie), where one fixed network both supplies and judges the statistics.
#   Section 8 measures why (`AdainConfig(shared_encoder=False)` is A's version; the `paper` preset uses it).
# - **AdaIN** on the channel statistics over time, then a **decoder** back to 263-d. The output keeps
#   the content's root trajectory (dims 0..3): where the body goes is content, how it moves is style.
#
# Training has two paths (A §3.2.2):
#
# | path | AdaIN input | loss |
# |---|---|---|
# | self-reconstruction | content code + the content's *own* statistics | $\mathcal{L}_{content} = \lVert P_{c\to c} - P_c\rVert_1$ (A Eq. 4) |
# | stylization | content code + a style clip's statistics | $\mathcal{L}_{style} = \lVert\mu(C_{c\to s})-\mu(C_s)\rVert_2^2 + \lVert\sigma(C_{c\to s})-\sigma(C_s)\rVert_2^2$ (A Eq. 3) |
#
# with $C_{c\to s} = E_c(P_{c\to s})$ the encoder's features *of the stylized motion*, and the total
# $\mathcal{L} = \lambda_{style}\mathcal{L}_{style} + \lambda_{content}\mathcal{L}_{content}$ (A Eq. 5).
# (Read literally, A Eq. 3 compares the AdaIN output with the style features — equal by construction,
# so the loss would be zero; like Huang & Belongie we measure the *decoded* motion.) The training runs in
# two steps: first encoder and decoder learn the self-reconstruction path alone (an autoencoder); then
# the encoder is **frozen** and the decoder learns A Eq. 5. A frozen encoder cannot lower
# $\mathcal{L}_{style}$ by changing how it measures; only the decoder's motion can.
# The style clips come from the retargeted mocap corpus, the content clips from the content corpus.
# The workbook also runs the self-reconstruction path on the style clips (`style_recon`, logged as
# `style_rec` and averaged into the content term), so the decoder learns what the mocap styles' poses
# look like; the $\mathcal{L}_{content}$ printed below is A Eq. 4 on the content clips alone.

# %%
def box(ax, xy, text, color):
    ax.text(*xy, text, ha="center", va="center", fontsize=8,
            bbox=dict(boxstyle="round,pad=0.4", fc=color, ec="0.3"))

def arrow(ax, a, b, color="0.3"):
    ax.annotate("", xy=b, xytext=a, arrowprops=dict(arrowstyle="->", color=color, lw=1.2))

fig, ax = plt.subplots(figsize=(9, 3.4))
ax.set_xlim(0, 10); ax.set_ylim(0, 4); ax.axis("off")
box(ax, (0.9, 3.2), "content $P_c$\n263-d", "#cfe2ff"); box(ax, (0.9, 0.8), "style $P_s$\n263-d", "#ffd8b1")
box(ax, (2.9, 3.2), "$E_c$ (conv)", "#e7f1ff"); box(ax, (2.9, 0.8), "$E_c(P_s)$", "#fff0e0")
box(ax, (2.9, 2.0), "$\\mu,\\sigma$ of $E_c(P_c)$", "#fff0e0")
box(ax, (5.0, 3.2), "AdaIN($C_c$, $\\mu,\\sigma$ of $P_c$)", "#e8f5e9")
box(ax, (5.0, 0.8), "AdaIN($C_c$, $\\mu,\\sigma$ of $C_s$)", "#e8f5e9")
box(ax, (7.0, 3.2), "decoder → $P_{c\\to c}$", "#f3e5f5"); box(ax, (7.0, 0.8), "decoder → $P_{c\\to s}$", "#f3e5f5")
box(ax, (9.0, 3.2), "$\\mathcal{L}_{content}$\nvs $P_c$", "white"); box(ax, (9.0, 0.8), "$\\mathcal{L}_{style}$\nfrozen $E_c(P_{c\\to s})$ vs $C_s$", "white")
for a, b in (((1.5, 3.2), (2.3, 3.2)), ((1.5, 0.8), (2.2, 0.8)), ((1.3, 2.9), (2.5, 2.1)), ((3.5, 3.2), (3.7, 3.2)),
             ((3.4, 2.1), (4.0, 3.0)), ((3.4, 3.0), (3.9, 1.0)), ((3.7, 0.8), (3.75, 0.8)), ((6.3, 3.2), (6.2, 3.2)),
             ((6.3, 0.8), (6.2, 0.8)), ((7.9, 3.2), (8.4, 3.2)), ((7.9, 0.8), (8.2, 0.8))):
    arrow(ax, a, b)
ax.text(5.0, 3.85, "self-reconstruction path", ha="center", fontsize=9, weight="bold")
ax.text(5.0, 0.1, "stylization path (style clips from the other corpus)", ha="center", fontsize=9, weight="bold")
_ = fig

# %% [markdown]
# ## 3. A live training run
# A short run with the course model's sizes: a few autoencoder steps, then the encoder frozen and the
# decoder trained on A Eq. 5, logging both losses on the training batches and on held-out validation
# clips (content clips of the val split paired with style clips of the style corpus's val split), as
# A Table 1 reports them.

# %%
from dataclasses import replace
cfg = A.AdainConfig.preset("course")
live_cfg = TrainConfig(steps=80, batch_size=16, lr=2e-3, warmup_steps=10, val_every=20, val_batches=2)
live_model, live = A.train_adain("course", paths["content"], paths["style"], seed=0, progress=False,
                                 config=replace(cfg, pretrain_steps=80), train_config=live_cfg)
pre = live_model.pretrain_history
print(f"autoencoder: L_content train {np.mean(pre['train']['content'][:10]):.2f} → "
      f"{np.mean(pre['train']['content'][-10:]):.2f}")
for key in ("content", "style"):
    tr = live["train"][key]
    print(f"decoder on A Eq. 5: L_{key:<8} train {np.mean(tr[:10]):.3f} → {np.mean(tr[-10:]):.3f}   "
          f"val {live['val'][key][0]:.3f} → {live['val'][key][-1]:.3f}")
fig, axes = plt.subplots(1, 2, figsize=(9, 2.6))
for ax, key in zip(axes, ("content", "style")):
    ax.plot(live["step"], live["train"][key], lw=0.8, alpha=0.6, label="train")
    ax.plot(live["val_step"], live["val"][key], "o-", label="validation")
    ax.set_title(f"$\\mathcal{{L}}_{{{key}}}$ (encoder frozen)"); ax.set_xlabel("step"); ax.set_yscale("log")
    ax.legend(fontsize=7)
fig.tight_layout()
_ = fig

# %% [markdown]
# Once the decoder must also match the style's statistics, $\mathcal{L}_{style}$ falls while
# $\mathcal{L}_{content}$ gives a little back: the two terms pull against each other, which is why A
# weighs them with $\lambda$s.

# %% [markdown]
# ## 4. The course checkpoint
# The packaged model was trained by `python -m mslib train adain --preset course --seed 0` (some
# minutes on one CPU core: the autoencoder steps, then the decoder steps), the same command as the
# fallback below. The course preset counts the content path twice in A Eq. 5 ($\lambda_{content} = 2$):
# `tools/adain_variants.py --only recipes` trained that recipe and the plain one on two seeds each and
# scored them on the val pairs of section 8; the recipe and the seed were chosen there, by a rule written
# down before the last run was scored, never on the benchmark's test pairs. Its history travels with it:
# the final validation content loss stays close to the training one, so the model reconstructs unseen
# clips as well as seen ones.

# %%
if course_path("adain").is_file():
    model = A.load_adain()
else:  # no packaged checkpoint: train it now (a few minutes)
    model, _ = A.train_adain("course", paths["content"], paths["style"], seed=0, out=course_path("adain"))
    model = A.load_adain()
from mslib.checkpoints import read_checkpoint
hist = read_checkpoint(course_path("adain"), "adain")["extra"]["history"]
train_c = np.mean(hist["train"]["content"][-50:])
print(f"steps {hist['step'][-1]}")
print(f"L_content  train {train_c:.3f}  val {hist['val']['content'][-1]:.3f}  "
      f"(val/train {hist['val']['content'][-1] / train_c:.2f})")
print(f"L_style    train {np.mean(hist['train']['style'][-50:]):.4f}  val {hist['val']['style'][-1]:.4f}")

# %% [markdown]
# ## 5. One content motion in all eight styles
# A walk from the content corpus's test split, transferred with one test clip of each style from the
# style corpus. Each style clip is only 32 frames; its statistics are enough.

# %%
content_test = ContentClips(paths["content"], "test", normalize=False, joints=True)
style_test = StyleClips(paths["style"], "test", normalize=False)
walk = next(content_test[i] for i in range(len(content_test)) if content_test[i]["content"] == "walk")
style_items = {s: next(style_test[i] for i in range(len(style_test)) if style_test[i]["style"] == s) for s in STYLES}
c_feat = walk["features"].numpy().astype(np.float64)
outputs = {s: model.transfer(c_feat, it["features"].numpy()) for s, it in style_items.items()}
fig = viz.plot_strip([walk["joints"].numpy()] + [outputs[s] for s in STYLES], n_frames=5,
                     row_labels=["content"] + list(STYLES))
_ = fig

# %% [markdown]
# In the 3-D viewer below, drag to turn the skeletons, scroll to zoom, and play, pause or scrub; feet light up while
# they touch the floor. (Without a running kernel, a still picture stands in for it.)

# %%
# NBVAL_IGNORE_OUTPUT
viz.MotionViewer([walk["joints"].numpy()] + [outputs[s] for s in ("angry", "depressed", "old", "proud")],
                 titles=["content", "angry", "depressed", "old", "proud"])

# %% [markdown]
# **Try it.** The explorer below runs the packaged model live: pick a content clip, a style and a method, and
# compare the output with its content and style clips; the bars are the independent style classifier's
# probabilities for the output. It opens on the style stage 1 moves most reliably: the non-neutral style whose
# transfers the evaluator recognised most often on the **val** pairs (`tools/adain_variants.py`), so the first
# thing you see is a transfer that works — then try the others, where it often does not. The cell after it
# calls the same function with fixed choices and prints them.

# %%
from mslib.notebook import demo_style, load_findings
DEMO = demo_style(load_findings("02_adain_variants")["strength"]["by_style"])
print(f"demo style: {DEMO}")

# %%
# NBVAL_IGNORE_OUTPUT
from mslib.explorers import explore_transfer, transfer_view
explore_transfer("c00000", DEMO, "adain", methods=["adain", "identity", "copy_style"])

# %%
print(transfer_view("c00000", DEMO, "adain").summary())

# %% [markdown]
# ## 6. Dynamic and static noise: A Fig. 2
# AdaIN moves two statistics. Paper A's Fig. 2 shows what each half does on its own: **variance-only**
# transfer rescales the content's fluctuations and carries the *dynamic noise* (shaking, jitter);
# **mean-only** transfer shifts the average pose and carries the *static noise* (a limb held at a
# wrong angle, an offset from the content). We measure both on 40 benchmark pairs:
# - **jitter**: the mean joint acceleration (m/s²), $\frac{1}{T\cdot 22}\sum_{t,j}\lVert p_{t+1,j}-2p_{t,j}+p_{t-1,j}\rVert\cdot f^2$;
# - **pose offset**: the mean joint distance (m) to the content motion.

# %%
from mslib.evaluation.bench import Evaluator, format_table, load_pairs, run_bench
from mslib.evaluation.metrics import ADAIN_HALVES as modes, transfer_noise

pairs = load_pairs(seed=0, n_pairs=200)
fig2 = transfer_noise(model, pairs[:40])  # per pair: (jitter, pose offset) of the content and each half
print(f"{'transfer':<14} {'jitter m/s²':>11} {'pose offset m':>13}")
for name, vals in fig2.items():
    j, o = np.mean(vals, 0)
    print(f"{name:<14} {j:>11.2f} {o:>13.3f}")

# %%
c, s = pairs[3]
rows = [c["joints"], decode(s["features"])] + [model.transfer(c["features"], s["features"], use_mean=m, use_std=v)
                                              for m, v in modes.values()]
fig = viz.plot_strip(rows, n_frames=5, row_labels=["content", f"style ({s['style']})"] + list(modes))
_ = fig

# %%
base_j = np.mean([j for j, _ in fig2["content"]])
for name in modes:
    j, o = np.mean(fig2[name], 0)
    print(f"{name:<14} jitter {j / base_j:.1f}× the content's, pose offset {o:.3f} m")
halves = [n for n in modes if n != "full"]
print("of the two halves, more jitter:", max(halves, key=lambda n: np.mean(fig2[n], 0)[0]),
      "| larger pose offset:", max(halves, key=lambda n: np.mean(fig2[n], 0)[1]))

# %% [markdown]
# Compare with A Fig. 2, where variance-only transfer showed the *dynamic* noise (shaking) and
# mean-only the *static* noise (a distorted arm). Read the two halves against each other above: the
# half that moves σ is the one that adds the jitter, and the half that moves μ is the one that shifts
# the pose away from the content — the paper's split. σ sets how far each channel swings over time,
# so a wrong σ shows up as motion that shakes; μ sets where each channel sits, so a wrong μ shows up as
# a pose held in the wrong place. The full transfer carries both kinds of noise — what stage 2
# (notebook 05) learns to remove.
#
# ## 7. On the benchmark
# The same 200 held-out pairs every method meets (notebook 07), scored by the independent evaluator:
# content accuracy (CRA), style accuracy (SRA) and their harmonic mean H.

# %%
evaluator = Evaluator()
rows = [run_bench(m, pairs=pairs, evaluator=evaluator) for m in ("adain", "identity", "copy_style")]
print(format_table(rows, notebook=True))
h = {r["method"]: r["h"] for r in rows}
print(f"H: adain − identity {h['adain'] - h['identity']:+.2f}, adain − copy_style {h['adain'] - h['copy_style']:+.2f}")

# %% [markdown]
# An honest reading: the course model clears both reference rows but stays below the workbook's bar of
# 0.65 for a method — stage 1 alone does not reach it; stage 2 (notebook 05) does. It is a trade, not a
# free lunch: the style strength
# that raises SRA lowers CRA (section 8), because a style clip's statistics carry some of its
# *content* too (a kick's raised leg) along with its style, and AdaIN cannot tell the two apart.
# Notebook 07 places this row beside the other papers' methods.

# %% [markdown]
# ## 8. Why the course model shares its encoder
# `python tools/adain_variants.py` trains three versions of stage 1 with the course sizes and scores
# them on pairs from the **val** splits (never the benchmark's test pairs), at three style strengths
# $w$ — the statistics AdaIN applies are $\mu_c + w(\mu_s-\mu_c)$ and likewise for $\sigma$, Huang &
# Belongie's content–style trade-off:
# - `separate_joint`: A §3.2.1 as written, a transformer $E_s$ on joint positions trained together
#   with everything else (the decoder also sees the content through a skip);
# - `separate_frozen`: the same $E_s$, first trained as part of an autoencoder, then frozen as the
#   network A Eq. 3 measures with;
# - `shared_frozen`: the course recipe above.
#
# It also scores the packaged checkpoint at several $w$: how the course preset's `style_strength`
# was chosen (on val pairs, before the benchmark was run).

# %%
found = load_findings("02_adain_variants", required=False)  # written by tools/adain_variants.py
if "variants" in found:
    print(f"{'variant':<16} {'w':>5} {'CRA':>6} {'SRA':>6} {'H':>6}   ({found['variants']['val_pairs']} val pairs, "
          f"{found['variants']['steps']} decoder steps)")
    for r in found["variants"]["rows"]:
        print(f"{r['variant']:<16} {r['strength']:>5.2f} {r['cra']:>6.1f} {r['sra']:>6.1f} {r['h']:>6.3f}")
    best = {}
    for r in found["variants"]["rows"]:
        best[r["variant"]] = max(best.get(r["variant"], 0.0), r["h"])
    print("best H per variant:", {k: round(v, 3) for k, v in best.items()})
if "strength" in found:
    st = found["strength"]
    if st["checkpoint"] != checkpoint_digest("adain"):
        print("note: measured on another adain.pt: re-run python tools/adain_variants.py --only strength")
    print(f"packaged checkpoint on the val pairs (course style_strength = {model.cfg.style_strength}):")
    for r in st["rows"]:
        print(f"  w = {r['strength']:.2f}: CRA {r['cra']:5.1f}  SRA {r['sra']:5.1f}  H {r['h']:.3f}")
if "recipes" in found:
    rec = found["recipes"]
    at = {}
    for r in rec["rows"]:
        if r["strength"] == model.cfg.style_strength:
            at.setdefault(r["recipe"], {})[r["seed"]] = r["h"]
    print(f"recipes at the course strength, val H by seed: " + "; ".join(
        f"{k} {', '.join(f's{s} {h:.3f}' for s, h in sorted(v.items()))} (mean {np.mean(list(v.values())):.3f})"
        for k, v in sorted(at.items())))
    print(f"adopted: {rec['adopted']}, seed {rec['packaged_seed']} (rule: {rec['rule']})")
if not found:
    print("no measurements yet: run python tools/adain_variants.py")

# %% [markdown]
# How to read the table: every variant trades content (CRA) for style (SRA) as $w$ grows; what differs is
# how good the trade is. With a separate $E_s$ — trained jointly, or frozen after pre-training — the decoder
# gives up far more content at the same strength than with one encoder for both, frozen after
# pre-training, which has the best H of the three. The strength sweep on the packaged checkpoint shows the
# same trade at finer steps, and the recipe rows how much one training run's luck moves H.

# %% [markdown]
# ## Exercise: mean-only AdaIN by hand
# Write `mean_only(x, style_mu)` for a (B, T, C) feature map: keep every channel's spread and shape,
# move its mean over time to `style_mu` (B, 1, C). Use only tensor operations (no `adain`).

# %%
def mean_only(x, style_mu):
    return x - x.mean(1, keepdim=True) + style_mu

# %%
# check
x = torch.randn(2, 30, 5) * 3 + 1
s_mu = torch.randn(2, 1, 5)
assert torch.allclose(mean_only(x, s_mu), adain(x, s_mu, torch.ones_like(s_mu), use_std=False), atol=1e-5)
assert torch.allclose(mean_only(x, s_mu).mean(1, keepdim=True), s_mu, atol=1e-5)
print("mean_only matches AdaIN's mean-only switch")
