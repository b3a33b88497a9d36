"""Paper D's ClusterStyle: the SMA (D Eq. 11), stage freezing, captions, CFG/guidance and SDEdit sampling."""
import numpy as np
import pytest
import torch

from mslib.checkpoints import course_path
from mslib.models.clusterstyle import (SMA, ClusterStyle, ClusterStyleConfig, content_caption, null_text)
from mslib.models.clusterstyle import Pipeline, pose_diversity
from mslib.models.clusterstyle.prototypes import PrototypeConfig
from mslib.models.clusterstyle.transfer import decode_rows, last_input
from mslib.models.common.vae import MotionVAE, VAEConfig
from mslib.motion.features import N_FEATURES, encode

VOCAB = ["<pad>", "<unk>", "a", "forward", "person", "walks"]


def tiny(stage="sma", seed=0):
    torch.manual_seed(seed)
    cfg = ClusterStyleConfig.preset("course", dim=16, layers=1, heads=2, ddim_steps=4)
    pcfg = PrototypeConfig.preset("course", dim=8, layers=1, heads=2, window=4)
    return ClusterStyle(cfg, pcfg, latent_tokens=2, latent_dim=4, vocab=VOCAB, stage=stage)


def tiny_pipeline(seed=0):
    torch.manual_seed(seed)
    vae = MotionVAE(VAEConfig(latent_tokens=2, latent_dim=4, dim=16, heads=2, layers=1, ff_mult=2, dropout=0.0))
    return Pipeline(tiny(seed=seed), vae)


def walk_features(n_frames=30):
    t = np.linspace(0, 1, n_frames)
    pos = np.zeros((n_frames, 22, 3))
    pos[:, :, 1] = np.linspace(0, 1.6, 22)[None]
    pos[:, :, 2] = 0.8 * t[:, None]
    pos[:, 20, 0] = 0.3 * np.sin(6 * t)  # a moving wrist
    return encode(pos)


def with_style_branch(pipe, seed=1):
    """Random weights in the SMA's style output (zero at initialisation), so the style branch matters."""
    torch.manual_seed(seed)
    for blk in pipe.model.denoiser.blocks:
        torch.nn.init.normal_(blk.sma.style_attn.out_proj.weight, std=0.3)
    return pipe


def test_config_presets_and_stored_configs():
    assert ClusterStyleConfig() == ClusterStyleConfig.preset("paper")  # the defaults are D's
    assert PrototypeConfig() == PrototypeConfig.preset("paper")
    course, pcourse = ClusterStyleConfig.preset("course"), PrototypeConfig.preset("course")
    assert (course.dim, course.ddim_steps, course.cfg_style, course.guide_weight) == (96, 20, 1.0, 1500.0)
    assert (pcourse.dim, pcourse.k_global, pcourse.k_local, pcourse.window) == (64, 3, 6, 10)
    assert ClusterStyleConfig().ddim_steps == 50 and PrototypeConfig().k_local == 30
    assert ClusterStyleConfig.preset("course", ddim_steps=4).ddim_steps == 4
    with pytest.raises(ValueError, match="ddim_stepz"):
        ClusterStyleConfig.preset("course", ddim_stepz=4)
    with pytest.raises(ValueError, match="preset"):
        PrototypeConfig.preset("laptop")
    with pytest.raises(ValueError, match="head"):
        PrototypeConfig.preset("course", head="kmeans")
    # the encoder always reads the 263-d vector: a stored input_dim of 263 loads, another is refused
    stored = {**pcourse.to_dict(), "input_dim": N_FEATURES}
    assert PrototypeConfig.from_dict(stored) == pcourse
    with pytest.raises(ValueError, match="input_dim"):
        PrototypeConfig.from_dict({**stored, "input_dim": 64})
    model = tiny()  # a model's stored config builds the same model
    again = ClusterStyle.from_config(model.config)
    assert again.cfg == model.cfg and again.style_cfg == model.style_cfg
    assert set(again.state_dict()) == set(model.state_dict())
    for name in ("clusterstyle", "clusterstyle_t2m", "clusterstyle_style"):  # the packaged configs load unchanged
        if course_path(name).is_file():
            config = torch.load(course_path(name), weights_only=True)["config"]
            assert PrototypeConfig.from_dict(config["prototypes"]) == pcourse
            if "model" in config:
                assert ClusterStyleConfig.from_dict(config["model"]).dim == course.dim


def test_sma_is_text_plus_lambda_times_style():
    torch.manual_seed(0)
    sma = SMA(8, 2, lambda_init=1.0)
    torch.nn.init.normal_(sma.style_attn.out_proj.weight)
    h, text, style = torch.randn(2, 3, 8), torch.randn(2, 4, 8), torch.randn(2, 5, 8)
    tp, sp = torch.zeros(2, 4, dtype=torch.bool), torch.zeros(2, 5, dtype=torch.bool)
    text_only = sma(h, text, tp)
    style_only = sma.style_attn(h, style, style, need_weights=False)[0]
    with torch.no_grad():
        sma.lam.fill_(2.5)
    assert torch.allclose(sma(h, text, tp, style, sp), text_only + 2.5 * style_only, atol=1e-5)
    keep = torch.tensor([1.0, 0.0])  # a dropped style silences the branch for that row only
    out = sma(h, text, tp, style, sp, keep)
    assert torch.allclose(out[1], text_only[1], atol=1e-6) and not torch.allclose(out[0], text_only[0])


def test_fresh_adapter_is_a_no_op():
    sma = SMA(8, 2)  # zero-initialised style output: the pre-trained model is unchanged at the start
    h, text, style = torch.randn(1, 3, 8), torch.randn(1, 2, 8), torch.randn(1, 4, 8)
    pad = torch.zeros(1, 2, dtype=torch.bool)
    assert torch.allclose(sma(h, text, pad, style, torch.zeros(1, 4, dtype=torch.bool)), sma(h, text, pad))


def test_captions_lose_their_style_words():
    assert content_caption("an old person walks forward slowly") == "a person walks forward slowly"
    assert content_caption("a person kicks with the left leg in a neutral style") == "a person kicks with the left leg"
    assert content_caption("a person waves with the right hand") == "a person waves with the right hand"


def test_null_text_keeps_one_zero_token():
    text, pad = torch.ones(3, 4, 2), torch.tensor([[False, False, True, True]] * 3)
    t, p = null_text(text, pad, torch.tensor([True, False, True]))
    assert torch.equal(t[0], text[0]) and (t[1] == 0).all()
    assert p[1].tolist() == [False, True, True, True] and torch.equal(p[0], pad[0])


def test_sma_stage_trains_only_the_style_branch():
    model = tiny().train()
    params = model.freeze_for_sma()
    assert {id(p) for p in params} == {id(p) for p in model.parameters() if p.requires_grad}
    batch = {"z": torch.randn(4, 2, 4), "caption": ["a person walks"] * 4, "style": torch.randn(4, 3, 8),
             "style_pad": torch.zeros(4, 3, dtype=torch.bool), "is_style": torch.tensor([1, 1, 0, 0])}
    logs = model.training_step(batch)
    assert set(logs) >= {"loss", "style_diff", "content_prior", "lambda"}
    logs["loss"].backward()
    assert model.denoiser.blocks[0].sma.lam.grad is not None
    assert model.denoiser.blocks[0].sma.text_attn.in_proj_weight.grad is None
    assert model.text.embed.weight.grad is None and model.denoiser.inp.weight.grad is None


def test_t2m_stage_ignores_style():
    model = tiny(stage="t2m").train()
    logs = model.training_step({"z": torch.randn(3, 2, 4), "caption": ["a person walks"] * 3})
    logs["loss"].backward()
    assert model.text.embed.weight.grad is not None
    assert model.denoiser.blocks[0].sma.style_attn.in_proj_weight.grad is None
    with pytest.raises(ValueError, match="stage"):
        tiny(stage="finetune")


def test_validation_is_repeatable_and_leaves_the_training_stream_alone():
    model = tiny(stage="t2m").eval()
    batch = {"z": torch.randn(3, 2, 4), "caption": ["a person walks"] * 3}
    torch.manual_seed(7)
    expected = torch.rand(3)
    torch.manual_seed(7)
    first = model.validation_step(batch)
    assert torch.equal(torch.rand(3), expected)  # the training draws go on as if no validation ran
    assert model.validation_step(batch) == first  # fixed timesteps and noise: one number per model


def test_transfer_shapes_determinism_and_bad_t0():
    pipe = tiny_pipeline()
    content, style = walk_features(30), walk_features(20)
    a = pipe.transfer(content, style, "a person walks forward", t0=500, seed=3)
    b = pipe.transfer(content, style, "a person walks forward", t0=500, seed=3)
    assert a.shape == content.shape and np.array_equal(a, b)
    assert pipe.generate(None, style, length=24, seed=0).shape == (24, 263)
    with pytest.raises(ValueError, match="t0"):
        pipe.transfer(content, style, t0=1000)
    with pytest.raises(ValueError, match="guide"):
        pipe.transfer(content, style, guide=("median", 0))


def test_guidance_follows_the_cosine_gradient_only_below_its_threshold():
    pipe = tiny_pipeline()
    style = pipe.style_tokens(walk_features(20))
    text, pad = pipe.text_tokens("a person walks")
    target = ("global", pipe.model.style.global_bank.prototypes[0, 1])
    plain = pipe.eps_fn(text, pad, style, 16)
    guided = pipe.eps_fn(text, pad, style, 16, target=target, weight=5.0, below=150)
    z = torch.randn(1, 2, 4)
    for t, differs in ((100, True), (400, False)):
        tt = torch.tensor([t])
        assert (not torch.allclose(plain(z, tt), guided(z, tt))) == differs
    g = pipe.guidance_grad(z, torch.tensor([100]), plain(z, torch.tensor([100])), 16, target)
    score = lambda zz: torch.nn.functional.cosine_similarity(  # noqa: E731
        pipe.model.style.features(pipe.vae.decode(pipe.model.sched.predict_x0(
            zz, torch.tensor([100]), plain(z, torch.tensor([100]))), [16]))[0][0], target[1], dim=0)
    with torch.no_grad():
        assert score(z + 1e-2 * g / g.norm()) > score(z)  # the gradient raises cos(f(x̂₀), target)


def test_sampler_gives_the_forward_pass_numbers():
    pipe = with_style_branch(tiny_pipeline())
    den = pipe.model.denoiser.eval()
    torch.manual_seed(2)
    text, pad = torch.randn(3, 1, 64), torch.zeros(3, 1, dtype=torch.bool)
    style, keep = torch.randn(3, 5, 8), torch.tensor([0.0, 1.0, 1.0])
    z, t = torch.randn(3, 2, 4), torch.tensor([900, 450, 7])
    with torch.no_grad():
        expected = den(z, t, text, pad, style, None, keep)
        assert torch.allclose(den.sampler(text, pad, style, keep)(z, t), expected, atol=1e-6)
        # no style kept, or no style at all: the style branch is silent
        assert torch.allclose(den.sampler(text, pad, style, torch.zeros(3))(z, t), den(z, t, text, pad), atol=1e-6)
        assert torch.allclose(den.sampler(text, pad)(z, t), den(z, t, text, pad), atol=1e-6)
    with pytest.raises(ValueError, match="one token"):
        den.sampler(torch.randn(3, 2, 64), torch.zeros(3, 2, dtype=torch.bool))


def test_batched_guidance_equals_the_separate_calls():
    """One denoiser call for the three CFG branches (and the conditions computed once) = three calls, D Eq. 12,
    then D Eq. 15's guidance term."""
    pipe = with_style_branch(tiny_pipeline())
    style = pipe.style_tokens(walk_features(20))
    text, pad = pipe.text_tokens("a person walks")
    null, null_pad = pipe.text_tokens(None)
    target = ("global", pipe.model.style.global_bank.prototypes[0, 1])
    s_t, s_s, w = 2.5, 1.5, 5.0
    fn = pipe.eps_fn(text, pad, style, 16, target=target, cfg_text=s_t, cfg_style=s_s, weight=w, below=300)
    den, z = pipe.model.denoiser, torch.randn(1, 2, 4)
    for step in (700, 100):
        t = torch.tensor([step])
        with torch.no_grad():
            e_uu = den(z, t, null, null_pad)  # ε(∅, ∅)
            e_cu = den(z, t, text, pad)  # ε(c, ∅)
            e_cs = den(z, t, text, pad, style)  # ε(c, s)
            eps = e_uu + s_t * (e_cu - e_uu) + s_s * (e_cs - e_cu)
            assert not torch.allclose(e_cs, e_cu)  # the style branch counts
        if step < 300:
            eps = eps - w * (1 - float(pipe.model.sched.alphas_cumprod[step])) ** 0.5 * pipe.guidance_grad(
                z, t, eps, 16, target)
        with torch.no_grad():
            assert torch.allclose(fn(z, t), eps, atol=1e-5)


def test_decode_rows_reads_only_the_receptive_field():
    torch.manual_seed(0)
    vae = MotionVAE(VAEConfig(arch="conv", latent_tokens=64, latent_dim=4, dim=16, layers=3, dropout=0.0, max_len=256,
                              down=4)).eval().double()
    z = torch.randn(1, 64, 4, dtype=torch.float64)
    with torch.no_grad():
        full = vae.decode(z, [256])
        for rows in (1, 64, 150, 256):  # 27, 27, 42 and all 64 of the latent tokens decoded
            assert torch.allclose(decode_rows(vae, z, rows), full[:, :rows], atol=1e-12)
        last = last_input(vae.conv.dec, 149)  # rows 0..149 read latent tokens 0..last, no further
        for j, reads in ((last, True), (last + 1, False)):
            moved = z.clone()
            moved[0, j] += 1.0
            assert bool((vae.decode(moved, [256])[:, :150] != full[:, :150]).any()) == reads


def test_prototype_tokens_replace_the_global_and_local_features():
    pipe = tiny_pipeline()
    s = pipe.style_tokens(walk_features(20))  # 19 rows, window 4 → 4 local tokens
    bank = pipe.model.style
    out = pipe.prototype_tokens(s, global_k=2, style=1)
    assert torch.equal(out[0, 0], bank.global_bank.prototypes[1, 2]) and torch.equal(out[0, 1:], s[0, 1:])
    out = pipe.prototype_tokens(s, local_perm=[3, 1], style=0)
    assert torch.equal(out[0, 1], bank.local_bank.prototypes[0, 3]) and torch.equal(out[0, 2], bank.local_bank.prototypes[0, 1])
    assert torch.equal(out[0, 3], bank.local_bank.prototypes[0, 3])


def test_nearest_global_prototype_finds_each_prototype_used_as_the_feature():
    pipe = tiny_pipeline()
    s = pipe.style_tokens(walk_features(20))
    bank = pipe.model.style.global_bank.prototypes  # (C, K, D)
    for c in range(bank.shape[0]):
        for k in range(bank.shape[1]):
            assert pipe.nearest_global_prototype(pipe.prototype_tokens(s, global_k=k, style=c)) == (c, k)
            scaled = pipe.prototype_tokens(s, global_k=k, style=c)
            scaled[0, 0] *= 7.0  # cosine: the length of the feature does not matter
            assert pipe.nearest_global_prototype(scaled) == (c, k)


def test_variants_take_one_seed_or_one_seed_per_variant():
    pipe = tiny_pipeline()
    content, style = walk_features(30), walk_features(20)
    k = pipe.model.style_cfg.k_global
    same = pipe.variants(content, style, kind="global", seed=4)
    listed = pipe.variants(content, style, kind="global", seed=[4] * k)
    assert len(same) == k and all(np.array_equal(a, b) for a, b in zip(same, listed))
    paired = pipe.variants(content, style, kind="global", seed=list(range(k)))
    assert np.array_equal(paired[0], pipe.variants(content, style, kind="global", seed=0, n=1)[0])
    assert not np.array_equal(paired[1], pipe.variants(content, style, kind="global", seed=0)[1])
    with pytest.raises(ValueError, match="seed"):
        pipe.variants(content, style, kind="global", seed=[0, 1, 2, 3, 4][: k + 1])


def test_pose_diversity_known_answers():
    f = walk_features(30)
    assert pose_diversity([f, f]) == 0.0
    g = f.copy()
    g[:, 4:67] += 0.01  # joints 1..21 moved 1 cm along x, y and z (√3 cm), the root not: mean over 22
    assert pose_diversity([f, g]) == pytest.approx(100 * 0.01 * 3 ** 0.5 * 21 / 22, rel=1e-3)
    with pytest.raises(ValueError, match="features_list"):
        pose_diversity([f])


@pytest.mark.skipif(not course_path("clusterstyle").is_file() or not course_path("vae").is_file(),
                    reason="course checkpoints not built yet")
def test_packaged_checkpoint_loads_and_transfers():
    from mslib.models.clusterstyle import load_pipeline
    pipe = load_pipeline()
    lam = [float(b.sma.lam.detach()) for b in pipe.model.denoiser.blocks]
    assert any(abs(v - 1.0) > 1e-3 for v in lam)  # λ was trained
    assert bool(pipe.model.style.global_bank.frozen)
    out = pipe.transfer(walk_features(40), walk_features(32), "a person walks forward", seed=0)
    assert out.shape == (39, 263) and np.isfinite(out).all()


