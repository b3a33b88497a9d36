# %% [markdown]
# # 08 · Appendix: the papers' claims, measured
#
# Notebooks 02–07 each teach one method. This appendix gathers, in one place, every claim of the four
# papers that the workbook tests: what the paper says, what the course models show on the **built-in**
# benchmark and — where it can be measured — on **real** motion capture, a verdict, one paragraph on what
# it means, and the command that reproduced the number. Nothing here is trained: every number but A Fig. 2's
# (recomputed live with the packaged stage 1, which is fast) is read from the tables the tools of `tools/` stored in `notebooks/data/` (each row names the commit and
# the checkpoints that made it), and every verdict is computed from them by the rule printed beside it.
#
# **How to read a verdict.** *holds* — the direction the paper reports shows up here; *does not hold* —
# it does not, which on this small CPU benchmark is a finding, not a bug. The papers measured on real
# datasets with their own evaluators and GPU-sized models, so only the **direction** of a claim carries
# over, never its numbers.
#
# Sources: the built-in benchmark is `python -m mslib bench --method all --pairs 200` (the README's table,
# stored by `python tools/update_docs.py readme`); the real pairs are `tools/real_bench.py` (the real
# data is not in the repository: `data_prep/README.md` says where it comes from).

# %%
import mslib
mslib.setup_notebook(seed=0)

import numpy as np

from mslib.checkpoints import course_path, trained_seed
from mslib.notebook import load_findings, readable_command

bench = {r["method"]: r for r in load_findings("07_bench")["builtin"]["rows"]}
real_section = load_findings("07_real_bench", required=False).get("real_pairs")
real = {r["method"]: r for r in real_section["rows"]["real"]} if real_section else {}
REFERENCES = ("identity", "copy_style")
verdicts = []  # (claim, built-in verdict, real verdict) for the summary at the end


def verdict(holds) -> str:
    return "n/a" if holds is None else ("holds" if holds else "does not hold")


def record(claim: str, builtin, on_real=None, command: str = "") -> None:
    """Print one claim's verdicts (built-in, real) and keep it for the summary table."""
    verdicts.append((claim, verdict(builtin), verdict(on_real)))
    print(f"{claim}\n  built-in: {verdict(builtin)}   real pairs: {verdict(on_real)}")
    if command:
        print(f"  reproduce: {readable_command(command)}")


def beats_references(rows: dict, method: str) -> bool | None:
    """H above both reference rows (identity: all content; copy_style: all style)."""
    if method not in rows:
        return None
    return rows[method]["h"] > max(rows[m]["h"] for m in REFERENCES)


print(f"built-in: {bench['identity']['pairs']} test pairs; real: "
      + (f"{real_section['pairs']} pairs, judged by classifiers trained on the real Xia train split" if real else
         "not stored"))
print(f"{'method':<13} {'H built-in':>10} {'H real':>7}")
for m in bench:
    print(f"{m:<13} {bench[m]['h']:>10.3f} {real[m]['h'] if m in real else float('nan'):>7.3f}")

# %% [markdown]
# ## Paper A — cross-dataset AdaIN transfer and the dual-stream denoiser
#
# **A Table 1** (transfer quality): AdaIN transfer with dual-path training keeps content and takes style
# — here, its H is above both reference rows, alone (stage 1) and with stage 2.

# %%
for m in ("adain", "adain+dsdn"):
    b, r = bench[m], real.get(m)
    print(f"{m:<11} built-in H {b['h']:.3f} (CRA {b['cra']:.1f}, SRA {b['sra']:.1f})"
          + (f" | real H {r['h']:.3f} (CRA {r['cra']:.1f}, SRA {r['sra']:.1f})" if r else ""))
print(f"references: built-in H {max(bench[m]['h'] for m in REFERENCES):.3f}"
      + (f", real H {max(real[m]['h'] for m in REFERENCES):.3f}" if real else ""))
for m in ("adain", "adain+dsdn"):
    record(f"A Table 1: {m} beats both reference rows on H", beats_references(bench, m), beats_references(real, m),
           "python -m mslib bench --method all --pairs 200")

# %% [markdown]
# Both stages clear the references, on the built-in pairs and on the real ones. But on real pairs the
# correction buys nothing (compare the two rows of the real column: CRA stays where it was, SRA falls, and H ends a
# little lower), where on built-in pairs it raises CRA far more than SRA falls: DSDN was trained to undo stage 1's artefacts on built-in
# motion, and that gain does not carry over to real motion.
#
# **A Table 2** (the ablation of stage 2): the dual-stream network with its gate beats either stream
# alone — here on the reconstruction loss $L_{rec}$ (A Eq. 11) and the velocity loss $L_{vel}$ (A Eq. 12)
# of the held-out (noisy, clean) pairs, the three modes trained on the same pairs with the same seed.

# %%
t2 = load_findings("05_dsdn_ablation")
rows = {r["mode"]: r for r in t2["rows"]}
print(f"{'mode':<8} {'val L_rec':>9} {'val L_vel':>9}")
for mode, r in rows.items():
    print(f"{mode:<8} {r['val_rec']:>9.3f} {r['val_vel']:>9.3f}")
record("A Table 2: the dual stream has the lowest L_rec", min(rows, key=lambda k: rows[k]["val_rec"]) == "dual",
       command=f"python {t2['command']} --out notebooks/data/05_dsdn_ablation.json")
record("A Table 2: the dual stream has the lowest L_vel", min(rows, key=lambda k: rows[k]["val_vel"]) == "dual",
       command=f"python {t2['command']} --out notebooks/data/05_dsdn_ablation.json")

# %% [markdown]
# The gate earns its place on reconstruction: the fused output is closer to the clean motion than either
# stream's. On smoothness it does not: the dynamic (LSTM) stream alone has by far the smoothest output, and
# the fused one is not smoother than the static stream either — the gate buys its poses with velocity error.
#
# **A §4.3** (what stage 2 is for): the correction lowers foot sliding (FSF) and jitter. The stored
# correction-strength sweep (κ = 0 is stage 1 alone) and the benchmark rows:

# %%
st = t2["strength"]
k0 = next(r for r in st["rows"] if r["strength"] == 0.0)
print(f"{'κ':>5} {'H':>6} {'FSF':>6} {'jitter':>7}   ({st['val_pairs']} val pairs)")
for r in st["rows"]:
    print(f"{r['strength']:>5.2f} {r['h']:>6.3f} {r['fsf']:>6.2f} {r['jitter']:>7.2f}")
record("A §4.3: stage 2 lowers foot sliding (FSF)", bench["adain+dsdn"]["fsf"] < bench["adain"]["fsf"],
       real["adain+dsdn"]["fsf"] < real["adain"]["fsf"] if real else None, "python -m mslib bench --method all")
record("A §4.3: stage 2 lowers jitter (every κ > 0 on val)",
       all(r["jitter"] < k0["jitter"] for r in st["rows"] if r["strength"] > 0), command=f"python {st['command']}")

# %% [markdown]
# **A Fig. 2** (where the noise comes from): variance-only transfer carries the *dynamic* noise (jitter),
# mean-only transfer the *static* noise (a pose held in the wrong place). Notebook 02 §6 measures both on
# 40 benchmark pairs with the packaged stage 1; the same numbers, recomputed here (AdaIN is fast):

# %%
from mslib.evaluation.bench import load_pairs
from mslib.evaluation.metrics import transfer_noise
from mslib.models.adain import load_adain

fig2 = {k: np.mean(v, 0) for k, v in transfer_noise(load_adain(), load_pairs(seed=0, n_pairs=40)).items()}
for name, (j, o) in fig2.items():
    print(f"{name:<14} jitter {j:5.2f} m/s²   pose offset {o:.3f} m")
record("A Fig. 2: variance-only carries more jitter than mean-only",
       fig2["variance only"][0] > fig2["mean only"][0], command="notebook 02 §6")
record("A Fig. 2: mean-only carries the larger pose offset",
       fig2["mean only"][1] > fig2["variance only"][1], command="notebook 02 §6")

# %% [markdown]
# Both halves show the split A describes: shaking rides on the variances, a displaced pose on the means.
#
# ## Paper B — MCM-LDM
#
# **B Table 1** (transfer quality): MCM-LDM keeps content and takes style — H above both references.
# **B §4.3** (the trajectory condition): with its trajectory condition the output keeps its feet better
# than a transfer that copies the content's path without it — here, lower FSF than AdaIN's.

# %%
b = bench["mcm_ldm"]
print(f"mcm_ldm built-in H {b['h']:.3f} (CRA {b['cra']:.1f}, SRA {b['sra']:.1f}), FSF {b['fsf']:.2f} against "
      f"adain's {bench['adain']['fsf']:.2f}")
record("B Table 1: mcm_ldm beats both reference rows on H", beats_references(bench, "mcm_ldm"),
       beats_references(real, "mcm_ldm"), "python -m mslib bench --method all --pairs 200")
record("B §4.3: mcm_ldm slides its feet less than adain", bench["mcm_ldm"]["fsf"] < bench["adain"]["fsf"],
       real["mcm_ldm"]["fsf"] < real["adain"]["fsf"] if real else None, "python -m mslib bench --method all")

# %% [markdown]
# **B Table 2** (ablations): each part matters — without the StyleRemover, without the trajectory
# condition, or with a style extractor trained from scratch instead of pre-trained, H falls; and without
# the trajectory the root path strays further (TSI). Short runs of each variant on the same 100 pairs.
# **The λ sweep**: the guidance scale has a best value in the middle — too little and the style is weak,
# too much and the content goes.

# %%
abl = load_findings("04_ablations")
ar = {r["key"]: r for r in abl["rows"]}
print(f"{'variant':<30} {'CRA':>6} {'SRA':>6} {'H':>6} {'TSI':>6}")
for r in abl["rows"]:
    print(f"{r['variant']:<30} {r['cra']:>6.1f} {r['sra']:>6.1f} {r['h']:>6.3f} {r['tsi']:>6.2f}")
for key in ("no_remover", "no_traj", "scratch_style"):
    record(f"B Table 2: '{ar[key]['variant']}' lowers H", ar[key]["h"] < ar["full"]["h"], command=ar[key]["command"])
record("B Table 2: without the trajectory the root path strays further (TSI)", ar["no_traj"]["tsi"] > ar["full"]["tsi"],
       command=ar["no_traj"]["command"])
lams = sorted((r for r in abl["rows"] if r["key"].startswith("lambda_")), key=lambda r: float(r["key"][7:]))
best = max(lams, key=lambda r: r["h"])
record(f"B λ sweep: H peaks inside the range (best λ = {best['key'][7:]})", best is not lams[0] and best is not lams[-1],
       command=best["command"])

# %% [markdown]
# All of B's ablations point the way the paper reports: the StyleRemover matters most (without it the
# output keeps the content's style, its SRA far below the full run's), and a pre-trained style extractor beats one
# learnt from scratch alongside the denoiser. The λ sweep peaks inside its range, as B reports: at the largest λ
# the style still gains, but the content falls far enough that H drops.
#
# ## Paper C — contrastive disentanglement
#
# **C Table 1** (the weight β of the contrastive terms): C reports its best trade at β = 0.3.
# **C Fig. 2** (what the terms buy): with InfoNCE and the triplet loss, style codes group by style
# (higher silhouette) than without. Both from short runs (`tools/contrastive_analysis.py`), measured on
# held-out clips. **C Fig. 3**: the codes of a style never seen in training still group together.

# %%
cf = load_findings("03_contrastive_findings")
print(f"{'β':>4} {'style silhouette':>17} {'1-NN style acc.':>16}")
for r in cf["sweep"]:
    print(f"{r['beta']:>4.1f} {r['silhouette']:>17.3f} {r['nn_accuracy']:>16.3f}")
best_beta = max(cf["sweep"], key=lambda r: r["nn_accuracy"])["beta"]
print(f"with the terms: silhouette {cf['with']['silhouette']:.3f}; without: {cf['without']['silhouette']:.3f}")
u = cf["unseen"]
print(f"unseen style '{cf['unseen_style']}': 1-NN purity {u['unseen_nn_purity']:.2f} (chance {u['chance_nn_purity']:.2f})")
record(f"C Table 1: the best β is C's 0.3 (here: {best_beta})", best_beta == 0.3, command=cf["command"])
record("C Fig. 2: the contrastive terms make style codes group better", cf["with"]["silhouette"] > cf["without"]["silhouette"],
       command=cf["command"])
record("C Fig. 3: an unseen style's codes group (1-NN purity ≥ 2× chance)",
       u["unseen_nn_purity"] >= 2 * u["chance_nn_purity"], command=cf["command"])
record("C §4: the course model beats both reference rows on H", beats_references(bench, "contrastive"),
       beats_references(real, "contrastive"), "python -m mslib bench --method all --pairs 200")

# %% [markdown]
# C's representation claims mostly do not reproduce here. In short CPU runs the contrastive terms make the style
# codes group only a little better than without them (C Fig. 2 holds in direction, but both silhouettes are below
# zero), the best β of the sweep is not C's, and the codes of a style never seen in training do not group
# (C Fig. 3) — one short run per β, so hold the differences against
# the seed spread of the recipe search below (one run's luck moved H by a few hundredths there). The packaged course model nevertheless beats both reference rows on H: its style encoder
# was first trained as an autoencoder and then frozen (notebook 03 §1), which is a departure from C, not C's
# joint training.
#
# ## Paper D — ClusterStyle
#
# **D Table 3** (the style encoder's head): learning prototypes by clustering gives better transfers
# than a plain classification head — here, SRA of the two heads on the same pairs, each trained for the
# same short run. **D Fig. 5** (intra-style diversity): one prototype per seed gives more diverse outputs
# than seeds alone.

# %%
cs = load_findings("06_clusterstyle_findings")
heads = {r["head"]: r for r in cs["table3"]["rows"]}
se = 100 * np.sqrt(0.25 / cs["table3"]["pairs"])
for h, r in heads.items():
    print(f"{h:<11} SRA {r['sra']:5.1f}  CRA {r['cra']:5.1f}  H {r['h']:.3f}")
print(f"one standard error of an SRA near 50 % on {cs['table3']['pairs']} pairs: ±{se:.1f} points")
f5 = cs["fig5"]["summary"]["transfer"]
print(f"transfers: prototype k with seed k more diverse than seeds alone in {f5['paired_beats_seeds']['diversity']}"
      f"/{f5['examples']} examples (diversity), {f5['paired_beats_seeds']['pose_cm']}/{f5['examples']} (pose)")
record("D Table 3: the prototype head beats the classification head on SRA",
       heads["prototypes"]["sra"] > heads["classifier"]["sra"], command=cs["table3"]["command"])
record("D Fig. 5: prototypes add diversity to transfers (most examples)",
       2 * f5["paired_beats_seeds"]["diversity"] > f5["examples"], command=cs["fig5"]["command"])
record("D §4: clusterstyle beats both reference rows on H", beats_references(bench, "clusterstyle"),
       beats_references(real, "clusterstyle"), "python -m mslib bench --method all --pairs 200")
record("D §4: clusterstyle's outputs are more diverse than adain's",
       bench["clusterstyle"]["diversity"] > bench["adain"]["diversity"],
       real["clusterstyle"]["diversity"] > real["adain"]["diversity"] if real else None, "python -m mslib bench --method all")

# %% [markdown]
# D's diversity claim holds — choosing a prototype moves the output in a way a new seed alone does not — and
# clusterstyle's outputs are more diverse than AdaIN's, on the built-in benchmark and on the real pairs.
# Its Table 3 does not point D's way on SRA: after the same short run the classification head's transfers read as
# their style a little more often than the prototype head's, within noise (notebook 06 §9). The classification head
# also keeps more content (CRA) and so scores a higher H — a gap wider than the seed spreads below, though from one
# short run per head.
#
# ## The recipe explorations, in one table each
# The course recipes were chosen on **validation** pairs by the tools below; notebooks 02–06 tell why.
# Here is the gist of each search, as stored. A's variants and C's earlier recipe candidates train many models
# and were measured on an earlier version of the built-in corpora (each row names its commit; C's course row
# is the current corpora's); the packaged
# checkpoints were retrained on the current corpora with the recipes they chose. The seed searches ran on the
# previous version of the corpora (the generator before its knees were fixed): each trained its course recipe with
# the other seeds of 0–2 and packaged the seed its rule chose; the current checkpoints are those seeds retrained
# (adain's search was run again on the current corpora and chose another seed).
# Then A's style strength, DSDN's κ, B's λ and D's guidance weight were chosen once more for the packaged
# models (notebooks 02, 04 §8, 05 and 06 §8), now with real val pairs beside the built-in ones, and the seeds were
# checked on both val sets as well (the last two tables of this section).
# Read them as a lesson in noise: the
# same recipe, trained again with another seed, lands higher or lower on the same 200 val pairs by as much as many of the differences between
# recipes and claims in this appendix. D's guidance grid scores the two guidance weights of D's
# sampler on val pairs (notebook 06 §8 says why the course keeps the style branch on).

# %%
av = load_findings("02_adain_variants")
print(f"A stage 1, where the style statistics come from (tools/adain_variants.py; best val H over w; stored at "
      f"commit {av['variants']['commit']}, on the corpora of that commit):")
best_var = {}
for r in av["variants"]["rows"]:
    best_var[r["variant"]] = max(best_var.get(r["variant"], 0.0), r["h"])
for k, v in best_var.items():
    print(f"  {k:<16} {v:.3f}")
ar = av["recipes"]
print(f"\nA stage 1, the course recipe at other seeds (tools/adain_variants.py --only recipes; val H at "
      f"w = {ar['course_strength']:g}, the course w when it ran):")
print("  " + "  ".join(f"seed {r['seed']} {r['h']:.3f}" for r in ar["rows"]
                       if r["recipe"] == "course" and r["strength"] == ar["course_strength"])
      + f"  | packaged before: {ar['packaged_h']:.3f}, "
      + ("kept" if ar["keep_packaged"] else f"replaced by seed {ar['best_seed']}"))
bs = load_findings("04_ablations")["seeds"]
print(f"B, the course recipe at other seeds (tools/mcm_ldm_ablations.py --only seeds; val H at λ = {bs['scale']:g}, "
      f"{bs['ddim_steps']} DDIM steps):")
packaged_seed = trained_seed(course_path("mcm_ldm"), "mcm_ldm")
print("  " + "  ".join(f"seed {r['seed']} {r['h']:.3f}" for r in bs["rows"])
      + f"  | best: seed {bs['best_seed']}; the packaged model: seed {packaged_seed}")
rec = load_findings("03_contrastive_recipes")
cseeds = rec["seeds"]
print("C, the course recipe at other seeds (tools/contrastive_findings.py seeds; val H at w = 1):")
print("  " + "  ".join(f"seed {r['seed']} {r['h']:.3f}" for r in sorted(cseeds["rows"], key=lambda r: r["seed"])
                       if r["strength"] == 1.0)
      + f"  | best: seed {cseeds['best_seed']}; the packaged model: seed "
      f"{trained_seed(course_path('contrastive'), 'contrastive')}")
ds = cs["seeds"]
print(f"D, the SMA stage at other seeds (tools/clusterstyle_findings.py --only seeds; val H on {ds['pairs']} pairs at "
      f"w = {ds['rows'][0]['guide_weight']:g}, the course w when it ran):")
print("  " + "  ".join(f"seed {r['seed']} {r['h']:.3f}" for r in sorted(ds["rows"], key=lambda r: r["seed"]))
      + f"  | best: seed {ds['best_seed']}; the packaged model: seed {trained_seed(course_path('clusterstyle'), 'clusterstyle')}")
print(f"\nC, the course recipe's candidates (tools/contrastive_findings.py val; H on {rec['val_pairs']} val pairs, "
      "the course row on the current corpora, the others on older ones — each row names its commit):")
for r in sorted(rec["rows"], key=lambda r: -r["h"])[:8]:
    print(f"  {r['variant']:<20} {r['h']:.3f}   ({r['commit']})")
g = cs["guidance"]
print(f"\nD, the guidance grid (tools/clusterstyle_findings.py --only guidance; {g['pairs']} {g['split']} pairs):")
for r in g["rows"]:
    print(f"  w {r['weight']:>6.0f}  s_s {r['cfg_style']:>3}  H {r['h']:.3f}")

# %% [markdown]
# ### The course knobs, checked on real motion
# Every knob above was first chosen on built-in val pairs. Real motion capture is the yardstick of this
# workbook, yet its test grid may never choose anything. So the knobs are also scored on **real val pairs**:
# the Xia train takes that neither real judge trained or stopped on (contents: their neutral takes; styles: all
# of them), judged by the real judges. Each knob then takes the value with the best *mean* of its built-in val H and
# its real val H. Two knobs are policies, so their rows are shown, not used: C's $w = 1$ (C's own transfer)
# and D's style scale $s_s = 1$ (the SMA's style branch on, notebook 06 §8). The built-in grid alone would switch
# the branch off; its last rows show whether real val pairs agree.

# %%
rv = load_findings("07_real_val")
print(f"{rv['pairs']} real val pairs ({len(rv['contents'])} neutral contents, {rv['styles']} style takes)\nrule: {rv['rule']}")
for m in ("adain", "dsdn", "contrastive", "contrastive_window", "mcm_ldm", "clusterstyle",
          "clusterstyle_style_scale"):
    part = rv[m]
    print(f"\n{m}: {part['knob']} = " + " ".join(f"{r['value']:>6g}" for r in part["rows"]))
    print(f"  {'real val H':<19}" + " ".join(f"{r['h']:>6.3f}" for r in part["rows"]))
    print(f"  {'built-in val H':<19}" + " ".join(f"{r['builtin_h']:>6.3f}" for r in part["rows"]))
    print(f"  {'mean':<19}" + " ".join(f"{r['mean_h']:>6.3f}" for r in part["rows"]))
    print(f"  chosen {part['chosen']:g} (packaged when it ran: {part['packaged']:g})"
          + (f"; kept by a policy ({part['policy']}); the rule's best: {part['best_by_rule']:g}" if "policy" in part else ""))

# %% [markdown]
# Read the rows against each other. Where the two val sets disagree, the mean decides, and it lands between them.
# A's $w$ and B's λ settle between their built-in peak and their real val peak, which lies at a stronger push:
# real styles need more than built-in ones. DSDN's κ is the peak of both. D's guidance disagrees most: past the
# weakest nonzero $w$, real val H falls far below its peak as $w$ grows (a guidance strong enough to carry a
# built-in style erases the content of a real take), and the mean keeps the built-in peak by a hair. C's real val H
# is still rising at the sweep's largest $w$ — at C's own $w = 1$ the transfer carries too little real style — but
# the course keeps C's transfer as the paper defines it, a policy fixed before these pairs were scored. C's
# transfer window does not move real val H: the real val contents are short Xia takes, which fit in one window, so
# the built-in half of the mean decides it. D's style branch is the reverse case: switching it off wins on built-in val pairs,
# while on real val pairs on and off score about the same, so the built-in gain does not carry over to real motion
# and the policy costs nothing there.

# %% [markdown]
# The seeds were checked the same way. Each seed search above packaged the seed with the best *built-in* val H, and
# one seed's luck on built-in pairs need not carry over to real motion. So every seed's checkpoint was also scored at
# its course knob on both val sets, and the seed with the best mean of its built-in and real val H is packaged (a
# rule fixed before any seed was scored on real pairs; the packaged seed keeps a tie). This comparison, too, was
# made on the previous corpora's checkpoints, so its numbers are not those of the checkpoints packaged now, except
# adain's: its seeds were trained and compared again on the current corpora, at its current course strength.

# %%
sd = rv["seeds"]
print(f"rule: {sd['rule']}")
for m in ("adain", "contrastive", "mcm_ldm", "clusterstyle"):
    part = sd[m]
    rows = sorted(part["rows"], key=lambda r: r["seed"])
    print(f"\n{m} at {part['knob']} = {part['value']:g}: " + "".join(f"{'seed ' + str(r['seed']):>9}" for r in rows))
    for key, label in (("builtin_h", "built-in val H"), ("h", "real val H"), ("mean_h", "mean")):
        print(f"  {label:<19}" + "".join(f"{r[key]:>9.4f}" for r in rows))
    print(f"  packaged when it ran: seed {part['packaged_seed']}; chosen: seed {part['chosen_seed']}; packaged now: "
          f"seed {trained_seed(course_path(m), m)}")

# %% [markdown]
# Every packaged seed is the rule's choice. A, B and C kept the seeds their built-in searches had chosen. D's
# changed: its built-in search had run at a stronger guidance, before the real val pairs weakened it, and packaged
# another seed, whose mean here falls short by a margin far inside the spread between seeds — the rule has no
# tolerance, so it decides even a near-tie. At the course guidance the seed now packaged also has the best built-in
# val H (the D line of the seed searches above, re-run at that guidance).
# The real val H of C's seeds lie close together: these pairs cannot tell C's seeds apart. Their contents are all
# short Xia takes, so they say nothing about long real motions from elsewhere, such as the HumanML3D contents of
# the real benchmark.

# %% [markdown]
# ## Summary
# Every claim above in one table, with its verdict on the built-in benchmark and on real pairs (n/a where
# the claim was only measured on one of them).

# %%
width = max(len(c) for c, _, _ in verdicts)
print(f"{'claim':<{width}}  {'built-in':<14} {'real pairs':<14}")
for claim, b, r in verdicts:
    print(f"{claim:<{width}}  {b:<14} {r:<14}")
print(f"\nhold on the built-in benchmark: {sum(b == 'holds' for _, b, _ in verdicts)} of "
      f"{sum(b != 'n/a' for _, b, _ in verdicts)}; on real pairs: {sum(r == 'holds' for _, _, r in verdicts)} of "
      f"{sum(r != 'n/a' for _, _, r in verdicts)}")
