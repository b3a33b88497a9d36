# %% [markdown]
# # 03 · Contrastive disentanglement: style transfer without labels (paper C)
#
# Paper C splits a motion into a **content code** (a tensor over time, h × t) and a **style code** (one
# vector), and builds a stylised motion by decoding the content code of a *target* motion with the
# style code of a *source* motion. Nothing tells the network which style a clip has: the pressure to
# separate content from style comes from two contrastive losses whose positives and negatives are
# drawn **inside the training pair itself**.
#
# **What you will learn**
# - the encoders E_c, E_s and the AdaIN generator G, and how a transfer is composed;
# - the five terms of C Eq. 1–5, each in maths beside the code that computes it, and why the
#   InfoNCE negatives are *other time steps of the same motion*;
# - training with two optimisers (generator side and discriminator) in the workbook's one loop;
# - C's findings measured: style-code clusters with and without the contrastive terms (C Fig. 2),
#   the β sweep (C Table 1), style interpolation (C Fig. 10–11) and an unseen style (C Fig. 3);
# - the benchmark row of the course model next to the two reference rows.

# %%
import mslib
mslib.setup_notebook(seed=0)

import numpy as np
import torch
import matplotlib.pyplot as plt

from mslib import viz
from mslib.checkpoints import course_path, read_checkpoint
from mslib.data.corpora import load_builtin
from mslib.data.datasets import MotionFolder
from mslib.data.styles import STYLES
from mslib.models import contrastive as C
from mslib.evaluation import embedding as E
from mslib.notebook import load_findings, readable_command
from mslib.motion.features import decode

paths = load_builtin(seed=0, progress=False)
cfg = C.ContrastiveConfig.preset("course")
print({k: getattr(cfg, k) for k in ("hidden", "style_dim", "down", "alpha", "beta", "gamma", "margin", "crop")})

# %% [markdown]
# ## 1. Two encoders and a generator
# - **E_c**: 3 Conv1d layers (the first with stride 2) and 3 residual blocks, then instance
#   normalisation over time → content code $E_c(M) \in \mathbb{R}^{h \times t}$, $t = T/2$;
# - **E_s**: 3 Conv1d layers and 3 residual blocks, averaged over time → style code
#   $E_s(M) \in \mathbb{R}^{l}$;
# - **G**: 4 residual blocks whose normalisations are AdaIN with a scale and shift predicted from the
#   style code, then back to T frames and 263 numbers per frame;
# - **D**: an MLP that scores windows of 4 frames (root height and root-relative joints, the numbers
#   the output positions are decoded from) as real or generated.
#
# **One departure from C, in the course preset only** (`content_skip=True`; the `paper` preset leaves it
# off): G's output is added to the target's own movement around its time mean, $x - \mu_t(x)$ ($x$ the
# normalised target). G then supplies the posture (the time mean, which the instance-normalised content
# code cannot carry) and any change of the movement. *Why:* in a few CPU minutes the paper-literal
# generator, which sees only the two codes, reconstructs poorly; section 4 scores it beside the other
# recipes on a validation draw (its row reproduces at commit 3748be4, where that option still lived). *What it costs:* the target's movement
# reaches the output without passing through E_c, so InfoNCE (C Eq. 3) has little left to enforce, and
# the posture comes from the style code alone — which is how the style clip's *content* can leak into
# a transfer (section 6 measures it).
#
# **A second departure, also in the course preset only** (`pretrain_steps`; the `paper` preset trains
# jointly from the first step, as C does): the course model trains in **two phases**. First E_c, E_s
# and G (with D) train as an autoencoder on C Eq. 1–2 alone. Then E_s is **frozen**, and E_c, G and W
# train on all of C Eq. 5. *Why:* trained jointly, C Eq. 4 also trains the network that judges it — E_s
# can satisfy the triplet by moving its codes rather than by G moving the style. Frozen, E_s is a fixed
# judge, like the loss network of notebook 02. Section 4 compares the recipes on a validation draw.
#
# **A third departure, in the course preset only** (`style_views`): in the autoencoder phase E_s also learns,
# without labels, to recognise two windows of one recording, so the judge it becomes knows what stays the same
# through a recording. *Why:* the judge an autoencoder alone trains tells some styles apart poorly, and G then
# does not make them. Section 4 builds up to it, with the loss in maths and the runs that adopted it.
#
# A transfer is $M^G = G\big(E_c(M^T) \,\big|\, E_s(M^S)\big)$: content from the target $M^T$, style from
# the source $M^S$. C draws both from one set $X$; here $X$ is the union of the two corpora, so a
# training pair is two random clips from content ∪ style corpus, 32 frames each (31 feature rows) —
# **no labels are read**. (The benchmark's transfers go one way, a content-corpus target and a
# style-corpus source; section 4 shows what training only in that direction does.)

# %%
torch.manual_seed(0)
model0 = C.ContrastiveModel(cfg).eval()
data = C.PairedClips(paths["content"], paths["style"], "val", crop=cfg.crop)
np.random.seed(0)
batch = torch.utils.data.default_collate([data[i] for i in range(4)])
target, source = batch["target"], batch["source"]
with torch.no_grad():
    c_t, s_s = model0.encode_content(target), model0.encode_style(source)
    fake = model0.generate(c_t, s_s, target.shape[1], target)
print("M^T", tuple(target.shape), "→ E_c", tuple(c_t.shape), "| M^S", tuple(source.shape), "→ E_s", tuple(s_s.shape))
print("M^G = G(E_c(M^T) | E_s(M^S))", tuple(fake.shape), "| D(M^G)", tuple(model0.discriminator(fake).shape))
n_params = {name: sum(p.numel() for p in getattr(model0, name).parameters())
            for name in ("content_encoder", "style_encoder", "generator", "discriminator")}
print("parameters:", n_params)

# %% [markdown]
# ## 2. The losses, one by one
# **C Eq. 1 — reconstruction.** Each input must come back from its own two codes:
# $\mathcal{L}_{rec} = \mathbb{E}\,\|G(E_c(M^S)|E_s(M^S)) - M^S\| + \mathbb{E}\,\|G(E_c(M^T)|E_s(M^T)) - M^T\|$.
# We average the per-frame Euclidean distance and divide by $\sqrt{263}$ so that it is of order 1 like
# the other terms (`C.reconstruction_loss`).
#
# **C Eq. 2 — adversarial.** The paper writes the original minimax GAN loss. Its generator term
# $\log(1 - D(M^G))$ saturates when D wins, so we use the **non-saturating** form: D minimises
# $-\log\sigma(D(M^S)) - \log(1-\sigma(D(M^G)))$, G minimises $-\log\sigma(D(M^G))$ (`C.adversarial_losses`).

# %%
x = torch.zeros(2, 5, 4)
print("rec of an error of 3 in every number:", round(C.reconstruction_loss(x + 3, x).item(), 3))
d_loss, g_loss = C.adversarial_losses(torch.zeros(3), torch.zeros(3))
print("an undecided D (logit 0): D loss", round(d_loss.item(), 3), "= 2 log 2, G loss", round(g_loss.item(), 3), "= log 2")

# %% [markdown]
# **C Eq. 3 — InfoNCE on content codes, with negatives from inside one motion.** Take time step $i$
# of the generated motion's content code as the query $q = E_c(M^G)_{:,i}$. Its positive is the same
# step of the target's code, $k^+ = E_c(M^T)_{:,i}$; its negatives are the **other steps of the same
# target**, $k^-_j = E_c(M^T)_{:,j}$, $j \ne i$ — a motion's own other moments are the hardest things
# to confuse it with, and no label is needed to pick them. The score is bilinear, $f(q,k) = q^\top W k$
# (divided by $\sqrt h$), with a learned $W$:
#
# $$\mathcal{L}_{nce} = -\,\mathbb{E}\Big[\log \frac{\exp f(q,k^+)}{\exp f(q,k^+) + \sum_{j} \exp f(q,k^-_j)}\Big].$$
#
# (The paper's typeset denominator omits the positive; we keep the usual CPC form, so the loss is
# ≥ 0.) Every step is a query in turn, so the scores form a $t \times t$ matrix per motion whose
# diagonal holds the positives: InfoNCE is a cross-entropy that asks each row to pick its diagonal.

# %%
t = c_t.shape[-1]
i = 5
print(f"one motion: t = {t} steps → query step {i}: 1 positive (step {i}), {t - 1} negatives (the other steps)")
W = torch.eye(cfg.hidden)
same = C.info_nce(c_t, c_t, W).item()
other = C.info_nce(c_t, c_t[torch.randperm(4)], W).item()
print(f"untrained E_c: InfoNCE with the target itself as query {same:.2f}, with another motion's steps {other:.2f} "
      f"(lower: {same < other}); chance level log t = {np.log(t):.2f}")

# %% [markdown]
# **C Eq. 4 — triplet on style codes.** The generated motion should carry the source's style and not
# the target's: query $q = E_s(M^G)$, positive $k^+ = E_s(M^S)$, negative $k^- = E_s(M^T)$, margin
# $\lambda = 1$:
# $$\mathcal{L}_{tri} = \mathbb{E}\big[\|q - k^+\| - \|q - k^-\| + \lambda\big]_+ .$$
#
# **C Eq. 5 — total.** $\mathcal{L} = \mathcal{L}_{rec} + \alpha\mathcal{L}_{gan} + \beta\mathcal{L}_{nce}
# + \gamma\mathcal{L}_{tri}$ with α = 1, β = 0.3, γ = 0.3.

# %%
q = torch.zeros(1, 3)
for neg in ([2.0, 0, 0], [0.5, 0, 0]):
    print(f"q = k+ = 0, k− at distance {np.linalg.norm(neg):.1f}: triplet {C.triplet_loss(q, q, torch.tensor([neg])).item():.2f}")
logs = model0.training_step({"target": target, "source": source})
print({k: round(float(v), 2) for k, v in logs.items()})

# %% [markdown]
# ## 3. Two optimisers in one loop
# The generator side (E_c, E_s, G, W) is optimised by the workbook's one loop, `mslib.training.fit`,
# given `parameters=model.generator_parameters()`. The discriminator has its **own** Adam, owned by the
# model: inside `training_step` it first takes one step on $M^S$ (real) against a *detached* $M^G$
# (fake), then the generator-side loss is returned to the loop. `C.train` calls the loop twice, once
# per phase; in the second, E_s no longer requires gradients, so the loop leaves it out. A short live
# run (fixed 20 + 20 steps):

# %%
torch.manual_seed(0)
live_cfg = C.ContrastiveConfig.preset("course", pretrain_steps=20, steps=20, batch_size=16)
live, live_hist = C.train(live_cfg, paths["content"], paths["style"], seed=0, progress=False, val=False)
for phase, tr, keys in (("phase 1, autoencoder (C Eq. 1–2, and §4's views term)", live.pretrain_history["train"],
                         ("rec", "adv", "views")),
                        ("phase 2, E_s frozen (C Eq. 1–5)", live_hist["train"], ("rec", "nce", "tri"))):
    print(phase)
    for k in keys:
        print(f"  {k:>4}: first 5 steps {np.mean(tr[k][:5]):.2f} → last 5 steps {np.mean(tr[k][-5:]):.2f}")
print("E_s trainable after phase 1:", any(p.requires_grad for p in live.style_encoder.parameters()))

# %% [markdown]
# ## 4. The course checkpoint
# The packaged model was trained by `OMP_NUM_THREADS=1 python -m mslib train contrastive --preset course
# --seed SEED` (the seed is printed below). Its recipe is the last one this section comes to: the two phases
# below, with a judge E_s that also learns, in the autoencoder phase, to recognise two windows of one recording
# (`style_views`, the end of this section). The recipe was judged on the **validation** pairs with seeds 0 and 2,
# and the packaged run is the one of those two with the higher H there, chosen before any test score.
# Picking the better of two flatters its validation H, so its honest score is the benchmark's test draw in
# section 6, which played no part in the choice. The history of its second phase is stored with the weights:

# %%
model = C.load()
blob = read_checkpoint(course_path("contrastive"), "contrastive")
hist = blob["extra"]["history"]
print("seed:", blob["extra"]["train_config"]["seed"] - 1, "| autoencoder steps:", model.cfg.pretrain_steps,
      "| steps with E_s frozen:", hist["step"][-1])
fig = viz.plot_curves({k: hist["train"][k] for k in ("rec", "nce", "tri", "adv", "d")}, title="course run, phase 2")
_ = fig

# %% [markdown]
# **Which recipe?** Models of the course sizes, scored by the independent evaluator on pairs from the
# **validation** splits (not the benchmark's test pairs), all at C's transfer ($w = 1$). The recipes were
# compared at a shorter schedule than the course preset's (the steps column). The first rows draw their
# training pairs *across* the corpora — $M^T$ from the content corpus, $M^S$ from the style corpus, the
# direction of the benchmark's transfers: C's joint training with the content skip and as C writes it
# (`literal`: no skip, no final instance norm), each for as many steps as the two phases together; the
# autoencoder phase alone (no contrastive terms at all); the two phases (`across`, also trained with two
# more seeds); and the two phases with C Eq. 2's discriminator shown the *target* clips as real motion too
# (`d_real_both`). Then the two phases with both clips of a pair drawn from the union of the corpora, C's
# one set $X$ (`union_short`, three seeds), and the same with its second phase twice as long (`union_mid`,
# three seeds). `skip_adain` is `union_short` with one change to the content skip: the target's movement
# is instance-normalised per dimension and rescaled by a σ that G predicts from the style code — A Eq. 2
# applied to the skip — so the autoencoder must carry in the style code how much each dimension moves,
# and the frozen E_s then judges the movement, not only the posture. `course_gain` (seeds 0 and 2) is
# `plain` (below) with a milder change to the skip: the target's movement multiplied per dimension by
# $\exp\big(A\,(E_s(M^S) - E_s(M^T))\big)$, $A$ a learned matrix that starts at zero. The gain is 1
# whenever the two codes agree, so reconstruction never trains $A$ — only C Eq. 2–4 in the second phase
# do — and the movement's scale follows the *difference* of two style codes, not one code that must
# also describe the clip. `course_long` (seeds 0 and 2) is `plain` with its second phase twice as
# long, 20000 steps. `plain` itself is `union_short` with its second phase four times as
# long (seed 0, like every row without a seed suffix), the course preset until the end of this section.
# The recipes after it each change one thing of `plain` (seeds 0 and 2); the last, `course_views`, is the
# course preset now, and its seed-0 run is the packaged checkpoint.
# FMD (lower = closer to real motion) is the benchmark's realism measure.
# "Content from style clip" is the share of transfers the content classifier names after the *style*
# clip's content. Made by `tools/contrastive_findings.py` (its command is printed; `train VARIANT` makes
# each model; variants whose options have left the library train at commit 3748be4, and each row names the
# commit that made it); this cell reads its JSON.

# %%
recipes = load_findings("03_contrastive_recipes")  # written by tools/contrastive_findings.py
print(recipes["val_pairs"], "val pairs; scored by")
for command in dict.fromkeys(r["command"] for r in recipes["rows"]):
    print(" ", readable_command(command))
print(f"{'recipe':>14} {'pairs':>7} {'steps (AE + Eq. 5)':>19} {'H':>6} {'CRA':>6} {'SRA':>6} {'FMD':>7} {'content from style clip %':>26}")
for r in recipes["rows"]:
    print(f"{r['variant']:>14} {r['pairs']:>7} {str(r['steps'][0]) + ' + ' + str(r['steps'][1]):>19} {r['h']:>6.3f} "
          f"{r['cra']:>6.1f} {r['sra']:>6.1f} {r['fmd']:>7.0f} {r['content_from_style_clip']:>26.1f}")
rec = {r["variant"]: r for r in recipes["rows"]}
BAR_H = 0.60  # the method's bar on the benchmark's default (test) draw when these recipes were compared
SEED_RUNS = {f"{name}_s{n}": name for name in ("across", "union_short", "union_mid") for n in (1, 2)}  # retrained with seeds 1, 2
SEED_RUNS.update({f"{name}_s2": name for name in ("course_gain", "course_long", "course_negatives", "course_views")})
by = {k: r["h"] for k, r in rec.items() if k not in SEED_RUNS}  # one run per recipe (seed 0)
runs = lambda name: np.array([by[name]] + [rec[k]["h"] for k, v in SEED_RUNS.items() if v == name])  # noqa: E731
across_seeds, short_seeds, mid_seeds = runs("across"), runs("union_short"), runs("union_mid")
print("`plain` above every recipe before it:", all(by["plain"] > by[k] for k in list(by)[:list(by).index("plain")]),
      "| autoencoder alone above joint training:", by["autoencoder"] > by["joint"],
      "| literal above joint training:", by["literal"] > by["joint"],
      f"| seed-0 runs at H ≥ {BAR_H:.2f} on val:", [k for k, h in by.items() if h >= BAR_H])
print("highest FMD (furthest from real motion):", max(recipes["rows"], key=lambda r: r["fmd"])["variant"])
print("D shown target clips as real, against `across`: CRA higher:", rec["d_real_both"]["cra"] > rec["across"]["cra"],
      "| SRA lower:", rec["d_real_both"]["sra"] < rec["across"]["sra"])
for new, old, change in (("union_short", "across", "pairs from the union"), ("plain", "union_short", "longer second phase")):
    print(f"{change}, against `{old}`: " + ", ".join(f"{k} {rec[new][k] - rec[old][k]:+.1f}" for k in ("cra", "sra"))
          + f", content from style clip {rec[new]['content_from_style_clip'] - rec[old]['content_from_style_clip']:+.1f} points")
for name, hs in (("across", across_seeds), ("union_short", short_seeds), ("union_mid", mid_seeds)):
    print(f"`{name}` over {len(hs)} seeds: H mean {hs.mean():.3f}, range {np.ptp(hs):.3f}")
sa, us = rec["skip_adain"], rec["union_short"]
print("movement scale from the style code (`skip_adain`) against `union_short`: "
      + ", ".join(f"{k} {sa[k] - us[k]:+.1f}" for k in ("cra", "sra", "content_from_style_clip")),
      f"| H below identity's (the ceiling table below):",
      sa["h"] < next(r["h"] for r in recipes["ceiling"]["rows"] if r["transfer"] == "statistics, w_mean=0.0, w_std=0.0"))

# %% [markdown]
# Read the table top down. Among the `across` recipes, the autoencoder alone beats C's joint training:
# trained jointly, the contrastive terms cost more than they give here — the content skip already keeps
# the movement (so InfoNCE has little left to do) and the triplet can be met by moving E_s. With E_s
# frozen (`across`) they add something on top of the autoencoder. The skip alone is no cure: trained
# jointly, the literal generator can beat it on H while its motions are the furthest from real ones (FMD).
#
# The next rows are about the discriminator. Trained across the corpora, D's real motions (the $M^S$)
# are style-corpus clips only, so D pulls every transfer toward style-corpus motion — its style, and
# with it its content (mostly locomotion). Shown the target clips as real too (`d_real_both`), the
# transfers keep their content and lose much of their style. `union_short` draws both clips of a pair
# from the union of the corpora, as C draws both from one set: D's real motions are then both corpora,
# and the losses also see style-corpus clips as targets and content-corpus clips as sources. The printed
# lines compare it with `across` (how much content comes back, and what it costs in style), and `plain`
# with `union_short`: the same recipe, trained longer. The seed table below says whether
# each lead is more than one run's luck.
#
# `course_gain` is compared with `plain`'s runs of the same seeds after the seed table below.
#
# `skip_adain` tried to make the frozen judge read the movement, and failed outright. The last column
# shows one reason: how much each dimension moves is itself content — a run swings its legs further than
# a walk, a punch moves an arm and little else — so a style code that carries it carries the style
# clip's content with it, and the transfer takes that content. (It was one short run; the seed spread
# below is far smaller than its fall.)
#
# **How much style?** C Fig. 10–11 mix two style codes. With the target's *own* code as one end, the
# mix is a style strength: $G\big(E_c(M^T) \,|\, E_s(M^T) + w\,(E_s(M^S) - E_s(M^T))\big)$, where
# $w = 1$ is C's transfer (and the course preset's), $w = 0$ gives the target back in its own style and
# $w > 1$ pushes past the style clip's code. The sweep asks whether another $w$ would do better on the
# same validation pairs (`tools/contrastive_findings.py strength`). An accuracy on a few hundred pairs
# moves by several points from the draw alone (the cell prints the binomial standard error), so read
# neighbouring rows as a plateau, not a ranking. And the sweep is of one run: a $w$ fitted to it need not
# suit another run of the same recipe (hold it against the seed spread below).

# %%
sweep = recipes["strength"]
print(f"{'w':>5} {'H':>6} {'CRA':>6} {'SRA':>6} {'content from style clip %':>26}")
for r in sweep["rows"]:
    print(f"{r['strength']:>5.1f} {r['h']:>6.3f} {r['cra']:>6.1f} {r['sra']:>6.1f} {r['content_from_style_clip']:>26.1f}")
best = max(sweep["rows"], key=lambda r: r["h"])
h_c = next(r["h"] for r in sweep["rows"] if r["strength"] == 1.0)
print(f"standard error of an accuracy near 50 % on {recipes['val_pairs']} pairs: ±{100 * np.sqrt(0.25 / recipes['val_pairs']):.1f} points")
print("best w on val:", best["strength"], f"(H {best['h'] - h_c:+.3f} against w = 1)",
      "| course preset's style_strength:", cfg.style_strength, "| the packaged model's:", model.cfg.style_strength)

# %% [markdown]
# **How much is one run's luck?** The draw of pairs is one source of noise; the training run is another.
# `plain`, trained with seeds 0, 1 and 2 and scored on the same validation pairs at C's transfer
# (`tools/contrastive_findings.py seeds`; the commands are printed, with a note: they were run while `plain` was
# the course preset, and the run packaged then, seed 2, is listed first), beside the three runs each of
# `union_mid`, `union_short` and `across` from the recipe table.
# Runs of `union_short`, `union_mid` and `plain` with the same seed share the seed and the
# recipe; only the length of the second phase differs. Most other rows of the recipe table are one or two runs
# per recipe, so hold their differences against this spread.

# %%
def seed_table(section: dict) -> dict:
    """Print a seeds section of the JSON (its commands, then a row per seed and w); seed → H at C's transfer."""
    print(readable_command(section["command"]))
    if "note" in section:
        print("note:", section["note"])
    print(f"{'seed':>5} {'w':>5} {'H':>6} {'CRA':>6} {'SRA':>6} {'FMD':>7} {'content from style clip %':>26}")
    for r in section["rows"]:
        print(f"{r['seed']:>5} {r['strength']:>5.1f} {r['h']:>6.3f} {r['cra']:>6.1f} {r['sra']:>6.1f} {r['fmd']:>7.0f} "
              f"{r['content_from_style_clip']:>26.1f}")
    return {r["seed"]: r["h"] for r in section["rows"] if r["strength"] == 1.0}


plain_runs = recipes["plain_seeds"]
h_w1 = seed_table(plain_runs)
plain_seeds = np.array([h_w1[k] for k in sorted(h_w1)])  # seeds 0, 1, 2, as the recipe table's extra runs
by_length = {rec[name]["steps"][1]: hs for name, hs in (("union_short", short_seeds), ("union_mid", mid_seeds))}
by_length[rec["plain"]["steps"][1]] = plain_seeds  # second-phase steps → H of seeds 0, 1, 2
for name, hs in (("plain", plain_seeds), ("union_mid", mid_seeds), ("union_short", short_seeds), ("across", across_seeds)):
    print(f"{name:>11}: H over {len(hs)} seeds: mean {hs.mean():.3f}, standard deviation {hs.std(ddof=1):.3f}, "
          f"range {np.ptp(hs):.3f}")
lengths = sorted(by_length)
for short, long in zip(lengths, lengths[1:]):
    print(f"second phase {short} → {long} steps, seed by seed: H {np.round(by_length[long] - by_length[short], 3)}")
then_packaged = plain_runs["rows"][0]["seed"]
print(f"the run packaged while `plain` was the preset (seed {then_packaged}) the best of these on val (the rule it was chosen by):",
      h_w1[then_packaged] == plain_seeds.max(), "| the recipe table's `plain` row is seed 0's run:", h_w1[0] == by["plain"])
print("every union_short seed above every `across` seed:", short_seeds.min() > across_seeds.max())
for new, new_hs, old, old_hs in (("union_short", short_seeds, "across", across_seeds),
                                 ("plain", plain_seeds, "union_short", short_seeds)):
    print(f"`{new}`'s lead over `{old}` (seed means) wider than either seed range:",
          new_hs.mean() - old_hs.mean() > max(np.ptp(new_hs), np.ptp(old_hs)))
print("`across`'s lead over joint and literal wider than its seed range:",
      all(by["across"] - by[k] > np.ptp(across_seeds) for k in ("joint", "literal")))
CANDIDATES = {"course_gain": "movement gain", "course_long": "second phase twice as long"}
candidate_runs = lambda name: {0: rec[name], 2: rec[f"{name}_s2"]}  # noqa: E731  (each trained with seeds 0 and 2)


def against_plain_runs(name: str, what: str) -> bool:
    """Each seed's changes against `plain`'s run of the same seed, and the rule's verdict."""
    leads = []
    for seed, r in candidate_runs(name).items():
        base = next(b for b in plain_runs["rows"] if b["seed"] == seed and b["strength"] == 1.0)
        leads.append(r["h"] - base["h"])
        print(f"{what} (`{name}`), seed {seed}, against `plain`'s run: H {leads[-1]:+.3f}, "
              + ", ".join(f"{k} {r[k] - base[k]:+.1f}" for k in ("cra", "sra", "content_from_style_clip")))
    adopted = bool(min(leads) > 0 and np.mean(leads) >= 0.02)
    print(f"`{name}` adopted (the rule fixed before it was scored: above the plain run on both seeds, mean lead ≥ 0.02):",
          adopted)
    return adopted


for name, what in CANDIDATES.items():
    against_plain_runs(name, what)
fig, ax = plt.subplots(figsize=(5, 3))
long_h = {seed: r["h"] for seed, r in candidate_runs("course_long").items()}
long_steps = rec["course_long"]["steps"][1]
for seed in range(len(plain_seeds)):
    line, = ax.plot(lengths, [by_length[n][seed] for n in lengths], "o-", label=f"seed {seed}")
    if seed in long_h:  # `course_long`: the same seed, twice `plain`'s second phase
        ax.plot([lengths[-1], long_steps], [by_length[lengths[-1]][seed], long_h[seed]], "o:", color=line.get_color())
ax.axhline(BAR_H, color="gray", ls="--", lw=1, label="the bar (on the test draw)")
ticks = lengths + [long_steps]
ax.set(xscale="log", xticks=ticks, xticklabels=ticks, xlabel="steps of the second phase (E_s frozen)",
       ylabel="H on val pairs", title="`plain`, longer second phase\n(dotted: `course_long`)")
ax.minorticks_off()
ax.legend(fontsize=8)
_ = fig

# %% [markdown]
# Three runs per recipe are few, so read the checks as a sketch: one training run's luck moves H by a few
# hundredths, as much as the gaps between several rows of the recipe table. Drawing the pairs from the
# union as C does lifted every run of its recipe above every run of the recipe before it. A longer second
# phase is a smaller step, so the cell compares it seed by seed — the same seed, a longer run — and the
# picture shows each seed's H as the phase grows.
#
# The movement gain leans the same way as `skip_adain`, far more mildly: on both seeds the transfers
# lose content (CRA); on one the style (SRA) rises, on the other it does not and more transfers take the
# style clip's content instead (the printed lines give each seed's changes). Whether it pays in H depends
# on the run, so by the rule fixed before the runs were scored it stays out of the preset, and `skip_gain` has
# left the library: `git checkout 3748be4`, then `tools/contrastive_findings.py train course_gain OUT`,
# reproduces it.
#
# Twice the second phase does not carry the trend on: on both seeds the longer run scores below the
# `plain` run of the same seed, losing both content (CRA) and style (SRA), and it moves further
# from real motion (FMD) — the printed lines give each seed's changes, the dotted lines in the picture the
# turn. More steps of C Eq. 5 are not what `plain` lacks, so by the rule fixed before these runs
# were scored the course preset keeps its second phase as it is
# (`tools/contrastive_findings.py train course_long OUT` reproduces the runs).

# %% [markdown]
# **Where does the style of a transfer live?** Two checks on the same validation pairs
# (`tools/contrastive_findings.py ceiling`), made for `plain`'s run packaged while it was the preset (seed 2;
# it is `mslib/checkpoints/contrastive.pt` as the repository's history holds it at commit 27342ef, and
# `ceiling plain=plain_s2.pt` scores it once saved under that name). First, transfers that learn nothing: A Eq. 2 applied to the
# raw 263-d features, partway — the target's time mean (its *posture*) moved a fraction $w_\mu$ toward
# the style clip's, its movement around that mean scaled per dimension by
# $(\sigma_\text{style}/\sigma_\text{target})^{w_\sigma}$. Second, the model's transfer split into
# its posture and the movement around it, each swapped for the target's own; and how far the posture moved
# toward the style clip's (the projection of the change of the joints' time mean onto the line from the
# target's to the style clip's; 0 = not at all, 1 = all the way). Paper A's course model from notebook 02,
# which moves the statistics of its encoder's features halfway toward the style clip's, is scored and
# measured the same way for comparison.

# %%
ceil = recipes["ceiling_plain"]  # the rows' "course model" is the model scored: here `plain`'s run
print(readable_command(ceil["command"]), "| style strength of the model:", ceil["strength"])
print(f"{'transfer':>45} {'H':>6} {'CRA':>6} {'SRA':>6} {'FMD':>7}")
for r in ceil["rows"]:
    print(f"{r['transfer']:>45} {r['h']:>6.3f} {r['cra']:>6.1f} {r['sra']:>6.1f} {r['fmd']:>7.0f}")
by_t = {r["transfer"]: r for r in ceil["rows"]}
plain_row = by_t["course model"]
stats_rows = [r for k, r in by_t.items() if k.startswith("statistics")]
print("posture moved toward the style clip's (median over pairs):", ceil["posture_moved_median"])
print("full posture swap: SRA above the model's:", by_t["statistics, w_mean=1.0, w_std=0.0"]["sra"] > plain_row["sra"],
      "| CRA below it:", by_t["statistics, w_mean=1.0, w_std=0.0"]["cra"] < plain_row["cra"])
identity_h = by_t["statistics, w_mean=0.0, w_std=0.0"]["h"]  # nothing moved: the identity transfer
posture_only = by_t["course model's posture, target's movement"]["h"]
movement_only = by_t["target's posture, course model's movement"]["h"]
print(f"H, the model's posture on the target's movement minus the model's: {posture_only - plain_row['h']:+.3f}")
print(f"H, the model's movement on the target's posture minus identity's: {movement_only - identity_h:+.3f}")
print("some no-learning mix scores above the model:", any(r["h"] > plain_row["h"] for r in stats_rows))
a_row = by_t["paper A course model"]
print("paper A's posture moved (median):", ceil["adain_posture_moved_median"],
      "| further than this model's:", ceil["adain_posture_moved_median"] > ceil["posture_moved_median"],
      "| A's H above this model's:", a_row["h"] > plain_row["h"])
print("paper A against this model: SRA higher:", a_row["sra"] > plain_row["sra"], "| CRA lower:", a_row["cra"] < plain_row["cra"],
      "| FMD higher:", a_row["fmd"] > plain_row["fmd"])

# %% [markdown]
# What this says about `plain`'s model: its style lives in the **posture**. Keep its posture and give
# back the target's own movement, and H barely moves (set the difference beside the standard error of an
# accuracy printed above); keep its movement and give back the target's posture, and it falls to about
# identity's or below (the mix with $w_\mu = w_\sigma = 0$). And the posture moves only part of the way toward the
# style clip's. The evaluator reads the posture too, but a *full* posture swap also carries the style
# clip's content (a punch's arm held forward), so CRA collapses. The best of these mixes moves the
# posture partway *and* scales the movement — with motions far from real ones (its FMD). Paper A's
# course model sits with those mixes: its posture moves further than this model's and its FMD is close
# to the mixes' — it buys its style (SRA) by moving more, at the price of realism and content, and ends
# near this model on H (the printed comparison says which is above). A better
# contrastive model would have to move the posture further without carrying the style clip's content,
# and change the movement, not only the posture; C's terms, as trained here, do not teach G to.

# %% [markdown]
# **Which styles does it reach?** The same validation pairs once more, split by the style clip's style
# (`tools/contrastive_findings.py styles`, with `by_style` from `mslib.evaluation.bench`): for `plain`'s
# run that was packaged while it was the preset (seed 2), each style's
# SRA and CRA, and the style its transfers are read as most often, beside the no-learning mix that moves
# only the posture, halfway ($w_\mu = 0.5$, $w_\sigma = 0$). One more column asks the model's own judge:
# can E_s, frozen after the autoencoder phase, tell that style's clips from the others — how often a style
# clip's nearest style code among the pairs' style clips *cut from other takes* has the same style (§5 says
# why not the same take). The labels are read only to score, as in C's findings below. (The picture also
# has the runs of the two recipes that come up at the end of this section, `course_negatives` and
# `course_views`; the packaged course model is `course_views`'s seed-0 run.)

# %%
by_style = recipes["styles"]
per_style = {t["transfer"]: {r["style"]: r for r in t["rows"]} for t in by_style["transfers"]}
model_rows, mix_rows = per_style["plain"], per_style["statistics, w_mean=0.5, w_std=0.0"]
print(readable_command(by_style["command"]))
print(f"{'style':>10} {'pairs':>5} | `plain`, seed 2: {'SRA':>4} {'CRA':>4} {'read most as':>13} {'E_s 1-NN':>8}"
      f" | half-posture mix: {'SRA':>4} {'CRA':>4}")
for st, r in model_rows.items():
    m = mix_rows[st]
    print(f"{st:>10} {r['n']:>5} | {r['sra']:>20.0f} {r['cra']:>4.0f} {r['read_as']:>13} {r['es_nn_purity']:>8.0f}"
          f" | {m['sra']:>22.0f} {m['cra']:>4.0f}")
n_min = min(r["n"] for r in model_rows.values())
print(f"one standard error of an accuracy near 50 % on {n_min} transfers: ±{100 * (0.25 / n_min) ** 0.5:.0f} points")
missed = sorted(model_rows, key=lambda st: model_rows[st]["sra"])[:2]  # the two styles the model reaches least
print("the two styles the model reaches least:", missed,
      "| read most as:", [model_rows[st]["read_as"] for st in missed])
print("… the half-posture mix reaches both more often:", all(mix_rows[st]["sra"] > model_rows[st]["sra"] for st in missed))
print("E_s's 1-NN against chance (a code with no style in it), the same two:",
      {st: f"{model_rows[st]['es_nn_purity']:.0f} % vs {model_rows[st]['es_chance']:.0f} %" for st in missed})
tri_end = float(np.mean(hist["train"]["tri"][-50:]))
print(f"C Eq. 4 at the end of the packaged run (mean of its last 50 logged values): {tri_end:.3f},"
      f" margin λ = {model.cfg.margin}")
fig, ax = plt.subplots(figsize=(8, 3))
names = list(model_rows)
width = 0.8 / len(per_style)
shown_as = {"statistics, w_mean=0.5, w_std=0.0": "half-posture mix (no learning)",
            "course model": "course model (course_views, seed 0)", "plain": "plain (seed 2)"}
for k, (label, rows) in enumerate(per_style.items()):
    ax.bar(np.arange(len(names)) + (k - (len(per_style) - 1) / 2) * width, [rows[st]["sra"] for st in names],
           width=width, label=shown_as.get(label, label))
ax.set(xticks=range(len(names)), xticklabels=names, ylabel="SRA on val pairs (%)", ylim=(0, 100),
       title="style by style: how often the evaluator reads the source's style")
ax.legend(fontsize=7, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.12))
fig.tight_layout()
_ = fig

# %% [markdown]
# `plain`'s SRA is far from even. Some styles it reaches more often than the no-learning mix; the two
# it reaches least, it turns into another style (the printed "read most as"). The half-posture mix
# reaches both of those far more often, so the evaluator needs no new movement to see them — the posture
# would do, if it were the *right* posture. And the model's own judge tells those styles' clips from
# the rest well above chance. So the difference is visible to E_s, and G does not make it. C Eq. 4 does
# not ask it to: its hinge wants E_s(M^G) nearer the source's code than the *target's*, by the margin,
# and says nothing about the codes of other styles — the posture of a neighbouring style, far enough from
# the target, already satisfies it (at the end of the packaged run's training the hinge's mean is a small
# fraction of its margin, printed above).

# %% [markdown]
# **Asking for more: every other source as a negative.** A direct test of that reading keeps C Eq. 4's
# hinge and margin and gives it more negatives: besides the target's code, the codes of the other sources
# in the batch (`style_negatives="batch"`, `triplet_loss_batch`, at commit 3748be4). With $q_i = E_s(M^G_i)$,
# $k^+_i = E_s(M^S_i)$, $k^-_i = E_s(M^T_i)$ and $d$ the Euclidean distance, over a batch of $B$ pairs:
#
# $$\mathcal{L}_{tri} = \frac{1}{B^2}\sum_{i}\Big([d(q_i,k^+_i) - d(q_i,k^-_i) + \lambda]_+
#   + \sum_{j \ne i}[d(q_i,k^+_i) - d(q_i,k^+_j) + \lambda]_+\Big)$$
#
# — C Eq. 4 itself when $B = 1$. Still no labels: another source may share the style of pair $i$'s (about
# one in eight), and the hinge then pushes a little the wrong way. The recipe `course_negatives` (`plain`
# with this term, seeds 0 and 2) was judged by the same rule, fixed before it was scored:

# %%
negatives_adopted = against_plain_runs("course_negatives", "the other sources as negatives")
for label in ("course_negatives", "course_negatives_s2"):
    rows = per_style[label]
    print(f"{label}: SRA by style", {st: round(rows[st]["sra"]) for st in names},
          "| the two `plain` reaches least, read most as:", {st: rows[st]["read_as"] for st in missed})
print(f"{missed[0]}: below the half-posture mix on both runs:",
      all(per_style[k][missed[0]]["sra"] < mix_rows[missed[0]]["sra"] for k in ("course_negatives", "course_negatives_s2")),
      "| read most as the same other style on both:",
      len({per_style[k][missed[0]]["read_as"] for k in ("course_negatives", "course_negatives_s2", "plain")}) == 1)

# %% [markdown]
# It does not pay. On both seeds H ends below `plain`'s run of the same seed, with less content
# (CRA) and no more style (SRA), so by the rule it stays out of the preset (the option has left
# the library; at commit 3748be4, `tools/contrastive_findings.py train course_negatives OUT` reproduces a run). Nor does it mend the styles it was aimed at: the one `plain` reaches
# least stays far below the half-posture mix on both runs, still read mostly as the same other style, and
# the second moves on one run only (the lines above and the picture). More
# negatives only help as far as the judge sees the difference, and this judge, E_s frozen after an
# autoencoder phase, tells those styles apart only in part (its 1-NN column). What `plain` would
# need is a judge that has learned what makes a style, which C Eq. 1–2 alone do not teach it.

# %% [markdown]
# **Teaching the judge: two windows of one recording.** Without labels, what can tell E_s what a style is?
# A recording keeps its style from start to end, while its content moves on (a later step, another arm
# swing). So in the autoencoder phase E_s gets one more task: from a window of a recording, find another
# window of the *same* recording among the batch's. With $z_i = E_s(M^S_i)/\lVert E_s(M^S_i)\rVert$, $z'_i$
# the same for another window of $M^S_i$'s recording (another crop of a content clip, another window of a
# style clip's take) and a temperature $\tau$:
#
# $$\mathcal{L}_{views} = -\frac{1}{2B}\sum_{i}\Big(\log\frac{e^{z_i^\top z'_i/\tau}}{\sum_j e^{z_i^\top z'_j/\tau}}
#   + \log\frac{e^{z_i^\top z'_i/\tau}}{\sum_j e^{z_j^\top z'_i/\tau}}\Big)$$
#
# — InfoNCE again, as C Eq. 3, but its positives are drawn *inside one recording* across time, where C Eq. 3's
# are the same instant of two motions. It is not in C. It is added as $\delta\,\mathcal{L}_{views}$ to the
# autoencoder phase only (`style_views` δ = 0.3, C's β and γ; `style_tau` τ = 0.1; `recording_nce`); the judge
# is then frozen as before. The same rule as for every recipe, fixed before the runs were scored
# (`course_views`, seeds 0 and 2). One prediction was written down with it: E_s's 1-NN column rises.

# %%
views_adopted = against_plain_runs("course_views", "a judge taught by two windows of one recording")
views_runs = ("course model", "course_views_s2")  # the packaged course model is `course_views`'s seed-0 run
es_nn = {k: np.mean([r["es_nn_purity"] for r in per_style[k].values()]) for k in ("plain", *views_runs)}
print("E_s 1-NN among other takes, mean over styles:", {k: f"{v:.0f} %" for k, v in es_nn.items()},
      "| above `plain`'s on both runs (the prediction):", all(es_nn[k] > es_nn["plain"] for k in views_runs))
for label in views_runs:
    rows = per_style[label]
    print(f"{label}: SRA by style", {st: round(rows[st]["sra"]) for st in names},
          "| the two `plain` reaches least, read most as:", {st: rows[st]["read_as"] for st in missed})
print("SRA above `plain`'s on the two styles it reaches least, run by run:",
      {k: {st: per_style[k][st]["sra"] > model_rows[st]["sra"] for st in missed} for k in views_runs})

# %% [markdown]
# This one passes the rule: on both seeds H is above `plain`'s run of the same seed, and on
# average by more than the rule asks (the lines above). The gain is in the style (SRA), bought with some
# content (CRA). The prediction held too: the judge tells styles apart more often than the autoencoder's
# (the mean 1-NN above), without ever seeing a label. Style by style, the picture and the lines show where the
# new judge helps and where it does not: the styles `plain` reaches least are not all mended.
# By the rule the recipe entered the course preset (`style_views=0.3` in `ContrastiveConfig.preset("course")`),
# and the better of its two runs on val, seed 0, chosen before any test score, is the packaged checkpoint this
# notebook loads. Two checks were made after that choice. The recipe was trained with a third seed, 1, and all
# three scored as `plain`'s were (`tools/contrastive_findings.py seeds`). And the packaged model was split into
# posture and movement as `plain`'s was above (`tools/contrastive_findings.py ceiling`):

# %%
course_runs = recipes["seeds"]
h_course = seed_table(course_runs)
course_seeds = np.array([h_course[k] for k in sorted(h_course)])
for name, hs in (("course", course_seeds), ("plain", plain_seeds)):
    print(f"{name:>7}: H over {len(hs)} seeds: mean {hs.mean():.3f}, standard deviation {hs.std(ddof=1):.3f}, "
          f"range {np.ptp(hs):.3f}")
print("each seed above `plain`'s run of the same seed:", {k: bool(h_course[k] > h_w1[k]) for k in sorted(h_course)},
      "| every seed above every `plain` seed:", course_seeds.min() > plain_seeds.max())
lead = course_seeds.mean() - plain_seeds.mean()
print(f"lead of the seed means {lead:+.3f}; wider than either seed range:", lead > max(np.ptp(course_seeds), np.ptp(plain_seeds)))
packaged_seed = course_runs["rows"][0]["seed"]
print(f"packaged run (seed {packaged_seed}) the best of the three on val:", h_course[packaged_seed] == course_seeds.max())
now = {r["transfer"]: r for r in recipes["ceiling"]["rows"]}
now_row = now["course model"]
print("posture moved toward the style clip's (median): `plain`", ceil["posture_moved_median"],
      "→ course model", recipes["ceiling"]["posture_moved_median"])
its_posture, its_movement = now["course model's posture, target's movement"], now["target's posture, course model's movement"]
print(f"course model, H of its posture on the target's movement minus its own: {its_posture['h'] - now_row['h']:+.3f}")
print(f"course model, H of its movement on the target's posture minus identity's: {its_movement['h'] - identity_h:+.3f}")
print("course model above every no-learning mix and paper A's model:",
      all(now_row["h"] > r["h"] for k, r in now.items() if k.startswith("statistics") or k == "paper A course model"),
      "| its FMD above that of `plain`'s run packaged before:", now_row["fmd"] > plain_row["fmd"])

# %% [markdown]
# Over three seeds the new recipe lies above `plain` run for run, and every one of its runs lies above every
# run of `plain`. The lead of the means is not wider than the new recipe's own seed range, though (the lines
# above): three runs a recipe show the direction more surely than the size. Seed 1, trained after the
# packaged run was chosen, scores higher on val than the packaged run. The choice stands: it was fixed by the
# rule before seed 1 existed, and by then the packaged run's test score was known, so switching now would let
# the test draw decide when to stop looking.
#
# The new model's style still lives in the posture. Keep its posture on the target's movement, and H moves
# by little; its movement alone is worth about identity. What the new judge changed is *which* posture: it
# moves a little further toward the style clip's (the medians above), and reaches the right style more often
# (the style-by-style lines). Changing the movement itself, the last point of the ceiling paragraph, is
# still out of reach of C's terms as trained here. And the gain has a price in realism: the FMD of its
# transfers is above that of `plain`'s run packaged before.

# %%
from mslib.evaluation.bench import Evaluator, format_table, load_pairs, run_bench

pairs = load_pairs(seed=0, n_pairs=200)
shown = [pairs[k] for k in (1, 2, 4)]
outs = [decode(model.transfer_features(c["features"], s["features"])) for c, s in shown]
motions, titles = [], []
for (c, s), o in zip(shown, outs):
    motions += [c["joints"], s["joints"], o]
    titles += [f"content: {c['content']}", f"style: {s['style']}", "transfer"]
fig = viz.plot_strip(motions, n_frames=5, view="side", titles=titles)
_ = fig

# %% [markdown]
# In the 3-D viewer below, drag to turn the skeletons, scroll to zoom, and play, pause or scrub; feet light up while
# they touch the floor. (Without a running kernel, a still picture stands in for it.)

# %%
# NBVAL_IGNORE_OUTPUT
viz.MotionViewer([shown[0][0]["joints"], shown[0][1]["joints"], outs[0]], titles=titles[:3])

# %% [markdown]
# ## 5. C's findings
# The findings need several models trained the same way with one setting changed: four runs for the
# β sweep (β = 0.3 is also the "with" run of (a)), one without the contrastive terms, one with a style
# left out — six short runs of the course model, each trained **jointly**, as C does: with E_s frozen,
# the contrastive terms could not shape the style codes these findings look at. They leave out the course
# preset's `style_views` (§4), so what shapes their codes is C's terms alone. They take about ten CPU minutes, too long for a
# notebook, so they were made once by the command
#
#     python tools/contrastive_analysis.py
#
# which writes `notebooks/data/03_contrastive_findings.json` (tables, silhouettes and the t-SNE points
# of the held-out style codes). The next cell **loads that file**. Style labels are read only to colour
# and score the codes, never in training.

# %%
results = load_findings("03_contrastive_findings")
labels = np.array(results["labels"])
print("short runs:", results["steps"], "steps each; held-out style clips:", len(labels))

# %% [markdown]
# ### (a) Style codes with and without the contrastive terms (C Fig. 2)
# Held-out style-corpus clips through E_s, projected with t-SNE and coloured by their style label.
# The silhouette score (−1 … 1, higher = tighter, better separated clusters) is measured on the
# codes themselves, not on the 2-D picture.

# %%
fig, axes = plt.subplots(1, 2, figsize=(9, 4))
for ax, key, name in zip(axes, ("with", "without"), ("with InfoNCE + triplet (β = γ = 0.3)", "without (β = γ = 0)")):
    xy = np.array(results[key]["tsne"])
    for s in STYLES:
        m = labels == s
        ax.scatter(xy[m, 0], xy[m, 1], s=8, label=s)
    ax.set_title(f"{name}\nsilhouette {results[key]['silhouette']:.2f}", fontsize=9)
    ax.set_xticks([]); ax.set_yticks([])
axes[1].legend(fontsize=7, markerscale=2, loc="best")
fig.tight_layout()
_ = fig
print(f"{'style codes':>28} {'silhouette':>11} {'1-NN style acc':>15} {'silhouette by content':>22}")
for key, name in (("with", "with (β = γ = 0.3)"), ("without", "without (β = γ = 0)")):
    r = results[key]
    print(f"{name:>28} {r['silhouette']:>11.3f} {r['nn_accuracy']:>15.3f} {r['silhouette_by_content']:>22.3f}")
print("C Fig. 2's claim (silhouette with > without):", results["with"]["silhouette"] > results["without"]["silhouette"])

# %% [markdown]
# Two more numbers per row: the leave-one-out **1-nearest-neighbour accuracy** (does a code's closest
# code have its style? chance is about 1/8), which sees local neighbourhoods that a silhouette
# averages away, and the silhouette of the same codes grouped by **content** label instead of style.
# The style clips are overlapping 32-frame windows cut from longer takes, so a clip's nearest code is
# often a window of the *same take*, a near copy that says nothing about style: the neighbour is
# searched among the clips of the other takes only.
# The same scores for the packaged course model, computed here. Its E_s was trained in the autoencoder
# phase only — C Eq. 1–2 and §4's two windows of one recording, never C Eq. 3–4 — so its codes show what that
# judge makes of the style:

# %%
clips_test, labels_test, contents_test, takes_test = E.style_clips(paths["style"], "test", with_content=True)
course_codes = model.style_codes(clips_test)
course_scores = E.code_scores(course_codes, labels_test, contents_test, takes_test)
print("course model:", {k: round(v, 3) for k, v in course_scores.items()})
print(f"its 1-NN style accuracy if a window of the same take may be the neighbour: "
      f"{E.nn_accuracy(course_codes, labels_test):.3f} ({len(set(takes_test))} takes, {len(takes_test)} clips)")

# %% [markdown]
# ### (b) The β sweep (C Table 1)
# β weighs InfoNCE. C reports that raising β lowers the **content distance** (output vs content
# motion) and raises the **style distance** (output vs style motion). Our distances, on 64 held-out
# *validation* pairs (not the benchmark's test pairs), in the normalised root-relative joint block
# $x$ (dims 4:67): content distance $= \frac{1}{T}\sum_t \|x_{out}(t) - x_{content}(t)\|/\sqrt{63}$;
# style distance $= \|\mathrm{Gram}(x_{out}) - \mathrm{Gram}(x_{style})\|_F / 63$ with
# $\mathrm{Gram}(x) = x^\top x / T$ (Gatys et al.'s style statistic, on features instead of network layers).

# %%
print(f"{'beta':>5} {'content dist':>13} {'style dist':>11} {'silhouette':>11} {'1-NN style acc':>15}")
for row in results["sweep"]:
    print(f"{row['beta']:>5.1f} {row['content_distance']:>13.3f} {row['style_distance']:>11.3f} "
          f"{row['silhouette']:>11.3f} {row['nn_accuracy']:>15.3f}")
cd = np.array([r["content_distance"] for r in results["sweep"]])
sd = np.array([r["style_distance"] for r in results["sweep"]])
print("content distance at β = 1 below β = 0:", bool(cd[-1] < cd[0]), "| falls at every step:", bool((np.diff(cd) < 0).all()))
print("style distance at β = 1 above β = 0:", bool(sd[-1] > sd[0]), "| rises at every step:", bool((np.diff(sd) > 0).all()))

# %% [markdown]
# ### (c) Style interpolation (C Fig. 10–11)
# Because the style is one vector, we can mix two: $G\big(E_c(M^T) \,|\, (1-w)E_s(M^{S_1}) + wE_s(M^{S_2})\big)$
# for $w = 0, 0.3, 0.6, 1$ — here with the course checkpoint, a held-out walk as the content and a
# depressed and a proud held-out walk as the two styles.

# %%
style_test = MotionFolder(paths["style"], "test", normalize=False, labels=("style", "content"))
pick = {s: next(i for i, r in enumerate(style_test.rows) if r["style"] == s and r["content"] == "walk")
        for s in ("depressed", "proud")}
walk = next(c for c, _ in pairs if c["content"] == "walk")
weights = (0.0, 0.3, 0.6, 1.0)
strip = C.interpolate_styles(model, walk["features"], style_test._arrays(pick["depressed"])[0],
                              style_test._arrays(pick["proud"])[0], weights)
fig = viz.plot_strip(strip, n_frames=5, view="side", titles=[f"depressed → proud, w = {w}" for w in weights])
_ = fig
heights = [float(np.mean(m[:, 15, 1] - m[:, 0, 1])) for m in strip]
print("head above pelvis (m):", [round(h, 3) for h in heights])

# %%
# NBVAL_IGNORE_OUTPUT
viz.MotionViewer([strip[0], strip[-1]], titles=["w = 0 (depressed)", "w = 1 (proud)"])

# %% [markdown]
# **Try it.** Slide $w$ from one style code to the other (C Fig. 10–11) and watch the posture move; the bars are
# the style classifier's probabilities. The cell after it prints the same function's numbers at fixed $w$.

# %%
# NBVAL_IGNORE_OUTPUT
from mslib.explorers import explore_interpolation, interpolation_view
explore_interpolation("c00000", "depressed", "proud", 0.5)

# %%
for w in (0.0, 0.5, 1.0):
    print(interpolation_view("c00000", "depressed", "proud", w).summary())

# %% [markdown]
# ### (d) An unseen style (C Fig. 3)
# A model trained with every *depressed* clip left out of both corpora: do the held-out depressed
# clips still fall together? Per-style silhouettes, and the fraction of depressed codes whose nearest
# neighbour from another take is also depressed (chance = its share of the clips):

# %%
u = results["unseen"]
xy = np.array(u["tsne"])
fig, ax = plt.subplots(figsize=(5, 4))
for s in STYLES:
    m = labels == s
    ax.scatter(xy[m, 0], xy[m, 1], s=8 if s != "depressed" else 16, label=s + (" (unseen)" if s == "depressed" else ""),
               marker="o" if s != "depressed" else "x")
ax.set_xticks([]); ax.set_yticks([]); ax.set_title("trained without depressed", fontsize=9)
ax.legend(fontsize=7, markerscale=2)
_ = fig
print("per-style silhouette:", {k: round(v, 2) for k, v in u["per_style"].items()})
print(f"all styles: silhouette {u['silhouette']:.3f}, 1-NN style accuracy {u['nn_accuracy']:.3f}")
print(f"depressed: nearest-neighbour purity {u['unseen_nn_purity']:.2f} (chance {u['chance_nn_purity']:.2f}); "
      f"{u['unseen_nn_purity_any_take']:.2f} if a window of the same take may be the neighbour")

# %% [markdown]
# ## 6. The benchmark
# The course model on the 200 held-out pairs of the default draw, next to the two reference rows
# (identity: all content; copy_style: all style). H is the harmonic mean of CRA and SRA; the workbook's bar
# for every method, since the corpora were fitted to real capture, is H ≥ 0.65 and above both reference rows.

# %%
evaluator = Evaluator()
rows = [run_bench(m, seed=0, n_pairs=200, pairs=pairs, evaluator=evaluator) for m in ("identity", "copy_style", "contrastive")]
print(format_table(rows, notebook=True))
h = {r["method"]: r["h"] for r in rows}
print("bar met (H ≥ 0.65 and above both references):",
      bool(h["contrastive"] >= 0.65 and h["contrastive"] > max(h["identity"], h["copy_style"])))

# %% [markdown]
# Where does the content go? For each transfer, ask the content classifier what it sees, and count how
# often it names the **style clip's** content instead of the content clip's. The style code is a time
# average of the whole style clip, so it also carries that clip's average pose — a punch's raised arm,
# a kick's lifted leg — and nothing in C Eq. 1–5 tells E_s to leave it out. Nor does §4's views term: two
# crops of one content clip share their content as well as their style.

# %%
outs_all = [np.asarray(decode(model.transfer_features(c["features"], s["features"]))) for c, s in pairs]
pred = np.array(evaluator.content.classes)[evaluator.score(outs_all)[0].argmax(1)]
own = np.array([c["content"] for c, _ in pairs])
theirs = np.array([s["content"] for _, s in pairs])
differ = own != theirs
print(f"pairs whose two clips differ in content: {int(differ.sum())}")
print(f"  output classified as the content clip's content: {100 * np.mean(pred[differ] == own[differ]):.1f} %")
print(f"  output classified as the style clip's content:   {100 * np.mean(pred[differ] == theirs[differ]):.1f} %")

# %% [markdown]
# ## Exercise
# Compute the InfoNCE loss of C Eq. 3 **by hand** (numpy only) for one motion whose content code has
# t = 3 steps, with W = I and h = 2. Store it in `answer`.
#
# query steps `Q` (h × t) and target steps `K` (h × t) are given below.

# %%
Q = np.array([[1.0, 0.0, 2.0], [0.0, 1.0, 0.0]])
K = np.array([[1.0, 0.5, 1.0], [0.0, 1.0, 1.0]])
# your code here: answer = ...
S = Q.T @ K / np.sqrt(2)                       # f(q_i, k_j), (t, t)
answer = float(np.mean([-S[i, i] + np.log(np.exp(S[i]).sum()) for i in range(3)]))

# %%
# check cell
expected = C.info_nce(torch.tensor(Q)[None], torch.tensor(K)[None], torch.eye(2, dtype=torch.float64)).item()
assert abs(answer - expected) < 1e-6, "score every query step against every key step, then a softmax cross-entropy on the diagonal"
print("correct:", round(answer, 4))
