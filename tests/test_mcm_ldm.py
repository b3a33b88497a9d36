"""MCM-LDM: the config, AdaLN-Zero blocks, condition routing (B Eq. 7–8), StyleRemover, CFG sampling (one
batched call = the two-call form), ablation switches, a tiny training run, the packaged transfer."""
import numpy as np
import pytest
import torch

from mslib.checkpoints import course_path
from mslib.data.corpora import load_builtin
from mslib.models import mcm_ldm as M
from mslib.models.common.diffusion import cfg_combine, ddim_sample

TINY = dict(width=32, heads=2, blocks=2, mlp_ratio=2, traj_layers=1, traj_down=4, steps=40, batch_size=8, lr=3e-3)
STYLE_CFG = {"dim": 16, "out_dim": 6, "heads": 2, "layers": 1}


def tiny(**kw):
    return M.MCMLDM(M.MCMConfig(**{**TINY, **kw}), latent_tokens=3, latent_dim=8, style_dim=6, style_cfg=STYLE_CFG)


def awake(model, seed=0):
    """Random weights everywhere (the zero-initialised gates too), so that every condition matters."""
    torch.manual_seed(seed)
    for p in model.parameters():
        torch.nn.init.normal_(p, std=0.1)
    return model.eval()


def conds(model, B=2, T=20, seed=0):
    g = torch.Generator().manual_seed(seed)
    zc, style = torch.randn(B, 3, 8, generator=g), torch.randn(B, 6, generator=g)
    traj = torch.randn(B, T, 3, generator=g)
    return model.conditions(zc, style, traj, torch.ones(B, T, dtype=torch.bool))


def test_config_presets_and_stored_configs():
    assert M.MCMConfig() == M.MCMConfig.preset("paper")  # the defaults are B's (as released)
    paper, course = M.MCMConfig(), M.MCMConfig.preset("course")
    assert (paper.width, paper.blocks, paper.mlp_ratio, paper.traj_layers, paper.lr) == (256, 9, 4, 2, 1e-4)
    assert (paper.p_drop_style, paper.cfg_scale, paper.ddim_steps) == (0.25, 2.5, 50)  # B §3.3, Eq. 5
    assert course == M.MCMConfig(width=96, heads=4, blocks=4, mlp_ratio=2, traj_layers=1, traj_down=8, patch=0,
                                 steps=6000, batch_size=64, lr=1e-3, ddim_steps=20, cfg_scale=2.0)  # both chosen on val
    assert M.MCMConfig.preset("course", use_traj=False).use_traj is False  # a B Table 2 switch on top
    with pytest.raises(ValueError, match="widht"):
        M.MCMConfig.preset("course", widht=8)
    with pytest.raises(ValueError, match="preset"):
        M.MCMConfig.preset("big")
    # a model's stored config (sizes beside the fields, patch resolved) rebuilds the same model
    m = tiny(patch=0)
    again = M.MCMLDM.from_config(m.config)
    assert again.cfg == M.MCMConfig(**{**TINY, "patch": 1}) and again.config == m.config
    assert set(again.state_dict()) == set(m.state_dict())
    with pytest.raises(ValueError, match="style_cfg"):
        M.MCMLDM.from_config({k: v for k, v in m.config.items() if k != "style_cfg"})
    # a retired research option loads when it holds the value the library always uses, else is refused
    for key, kept in M.MCMConfig.RETIRED.items():
        assert M.MCMLDM.from_config({**m.config, key: kept}).cfg == again.cfg
    for key, other in {"remover_norm": "token", "content_bottleneck": 8, "content_noise": 0.1, "traj_frames": 12}.items():
        with pytest.raises(ValueError, match=key):
            M.MCMLDM.from_config({**m.config, key: other})
    # the packaged checkpoint's stored config: the course preset with patch resolved, the retired keys at their values
    stored = torch.load(course_path(M.NAME), weights_only=True)["config"]
    assert {k: stored[k] for k in M.MCMConfig.RETIRED if k in stored} == \
        {k: v for k, v in M.MCMConfig.RETIRED.items() if k in stored}
    assert M.MCMConfig.from_dict(stored) == M.MCMConfig.preset("course", patch=stored["patch"])


def test_adaln_zero_block_starts_as_identity():
    blk = M.Block(16, 2, 2)
    h, zero = torch.randn(2, 5, 16), torch.zeros(2, 1, 3, 16)
    assert torch.equal(blk(h, zero, zero), h)  # gates α = 0: both branches closed
    m = tiny()  # and the zero-initialised MLP_s, MLP_t give zero modulations whatever the conditions
    mod_style, mod_traj = m.modulations(torch.randn(2, 32), torch.randn(2, 32))
    assert mod_style.shape == mod_traj.shape == (2, 1, 2, 3, 32) and not mod_style.any() and not mod_traj.any()


def test_modulations_are_each_blocks_own_mlps():
    m = awake(tiny(blocks=3))
    c_style, c_traj = torch.randn(2, 32), torch.randn(2, 32)
    mod_style, mod_traj = m.modulations(c_style, c_traj)  # B Eq. 7, block by block
    for k, blk in enumerate(m.blocks):
        assert torch.equal(mod_style[:, 0, k].reshape(2, -1), blk.ada_attn(c_style))
        assert torch.equal(mod_traj[:, 0, k].reshape(2, -1), blk.ada_mlp(c_traj))
    stacked = m.modulations(c_style, c_traj, m.ada_weights())  # the sampler's form: one product per condition
    assert all(torch.allclose(a, b, atol=1e-6) for a, b in zip(stacked, (mod_style, mod_traj)))


def test_style_on_attention_branch_trajectory_on_mlp_branch():
    torch.manual_seed(0)
    blk = M.Block(16, 2, 2).eval()
    h, zero = torch.randn(2, 5, 16), torch.zeros(2, 1, 3, 16)
    a, b = torch.randn(2, 1, 3, 16), torch.randn(2, 1, 3, 16)
    with torch.no_grad():  # the inference attention path, as the sampler runs it
        assert torch.equal(blk(h, zero, a), blk(h, zero, a))
        assert not torch.allclose(blk(h, a, zero), blk(h, b, zero))  # the style moves the attention branch
        assert not torch.allclose(blk(h, zero, a), blk(h, zero, b))  # the trajectory moves the MLP branch
        x = torch.nn.functional.layer_norm(h, (16,), eps=1e-6) * (1 + a[:, :, 1]) + a[:, :, 0]
        attn = blk.attn(x, x, x, need_weights=False)[0]  # the module's own call
        assert torch.allclose(blk(h, a, zero), h + a[:, :, 2] * attn, atol=1e-6)  # B Eq. 8, first line
        inference = blk(h, a, b)
    with torch.enable_grad():  # the training path (the module's attention) gives the same numbers
        assert torch.allclose(blk(h, a, b).detach(), inference, atol=1e-6)


def test_style_remover_drops_a_token_and_removes_statistics_across_tokens():
    torch.manual_seed(0)
    rem = M.StyleRemover(4, 8, 16, 2, 1).eval()  # InstanceNorm of each latent channel over the tokens
    z = torch.randn(2, 4, 8)
    out = rem(z)
    assert out.shape == (2, 3, 16)
    scale, shift = torch.rand(2, 1, 8) + 0.5, torch.randn(2, 1, 8)
    assert torch.allclose(rem(z * scale + shift), out, atol=1e-4)  # per-channel statistics are gone
    with pytest.raises(ValueError, match="patch"):
        M.StyleRemover(4, 8, 16, 2, 1, patch=3)


def test_denoiser_shapes_and_ablation_switches():
    m = tiny()
    cond = conds(m)
    assert cond["content"].shape == (2, 2, 32)  # N − 1 content tokens
    eps = m.denoise(torch.randn(2, 3, 8), torch.tensor([5, 900]), cond)
    assert eps.shape == (2, 3, 8)
    no_rem = tiny(use_remover=False)
    assert no_rem.remover is None and conds(no_rem)["content"].shape == (2, 3, 32)
    no_traj = tiny(use_traj=False)
    assert no_traj.traj is None and float(conds(no_traj)["traj"].abs().sum()) == 0.0
    scratch = tiny(pretrained_style=False)
    assert scratch.style_net is not None and tiny().style_net is None


def test_patches_group_consecutive_latent_tokens():
    assert (M.auto_patch(4), M.auto_patch(7), M.auto_patch(50), M.auto_patch(200)) == (1, 1, 5, 20)
    z = torch.arange(2 * 6 * 3, dtype=torch.float32).reshape(2, 6, 3)
    assert torch.equal(M.patchify(z, 2)[:, 1], torch.cat([z[:, 2], z[:, 3]], -1))  # tokens 2, 3 side by side
    cfg = M.MCMConfig(width=32, heads=2, blocks=2, mlp_ratio=2, traj_layers=1, traj_down=4, patch=2)
    m = M.MCMLDM(cfg, latent_tokens=6, latent_dim=8, style_dim=6)
    assert (m.p, m.m, m.n_content, m.config["patch"]) == (2, 3, 2, 2)
    g = torch.Generator().manual_seed(0)
    cond = m.conditions(torch.randn(2, 6, 8, generator=g), torch.randn(2, 6, generator=g),
                        torch.randn(2, 20, 3, generator=g), torch.ones(2, 20, dtype=torch.bool))
    assert cond["content"].shape == (2, 2, 32)
    assert m.denoise(torch.randn(2, 6, 8), torch.tensor([3, 700]), cond).shape == (2, 6, 8)
    with pytest.raises(ValueError, match="patch"):
        M.MCMLDM(M.MCMConfig(width=32, heads=2, blocks=1, patch=4), latent_tokens=6, latent_dim=8, style_dim=6)


def test_cfg_sample_scale_one_is_the_conditional_model():
    m = awake(tiny())
    cond = conds(m, B=1)
    null = m.style_proj(torch.zeros(1, 6))
    a = m.sample(cond, null, (1, 3, 8), scale=1.0, steps=10, generator=torch.Generator().manual_seed(1))
    b = ddim_sample(lambda x, t: m.denoise(x, t, cond), (1, 3, 8), m.sched, n_steps=10,
                    generator=torch.Generator().manual_seed(1))
    assert torch.allclose(a, b, atol=1e-5)
    c = m.sample(cond, null, (1, 3, 8), scale=2.5, steps=10, generator=torch.Generator().manual_seed(1))
    assert not torch.allclose(a, c)


@pytest.mark.parametrize("patch", [1, 3])
def test_batched_cfg_sampler_equals_the_two_call_form(patch):
    """B Eq. 5 as written — one denoiser call with the style, one with ∅, per step — against the sampler's one
    batched call on both (and its stacked MLP weights): the same latents up to float rounding."""
    m = M.MCMLDM(M.MCMConfig(**{**TINY, "patch": patch}), latent_tokens=6, latent_dim=8, style_dim=6)
    awake(m, seed=patch)
    g = torch.Generator().manual_seed(0)
    zc, style, traj = torch.randn(2, 6, 8, generator=g), torch.randn(2, 6, generator=g), torch.randn(2, 20, 3, generator=g)
    with torch.no_grad():
        cond = m.conditions(zc, style, traj, torch.ones(2, 20, dtype=torch.bool))
        null = m.style_proj(torch.zeros(1, 6))
        uncond = {**cond, "style": null.expand(2, -1)}
        for scale in (0.0, 2.5):
            def two_calls(x, t):
                return cfg_combine(m.denoise(x, t, uncond), m.denoise(x, t, cond), scale)
            want = ddim_sample(two_calls, (2, 6, 8), m.sched, n_steps=12, generator=torch.Generator().manual_seed(3))
            got = m.sample(cond, null, (2, 6, 8), scale=scale, steps=12, generator=torch.Generator().manual_seed(3))
            assert got.shape == want.shape and torch.allclose(got, want, atol=1e-5, rtol=1e-5)
            assert got.abs().max() > 0.1  # a real answer, not a trivially small one
        other = m.sample(cond, null * 0 + 1, (2, 6, 8), steps=12, generator=torch.Generator().manual_seed(3))
        assert not torch.allclose(other, got, atol=1e-3)  # the null style is the second branch's


def test_training_reduces_loss_and_dropped_style_gets_no_gradient():
    torch.manual_seed(0)
    n = 16
    tens = {"z0": torch.randn(n, 3, 8), "zc": torch.randn(n, 3, 8), "style": torch.randn(n, 6),
            "traj": torch.randn(n, 24, 3), "length": torch.full((n,), 24)}
    tens["z0"] = tens["zc"] * 0.8  # a learnable map from the content condition
    m = tiny(p_drop_style=1.0)
    for p in m.parameters():
        if p.dim() > 1:
            torch.nn.init.normal_(p, std=0.1)
    loss = m.training_step(tens)["loss"]
    loss.backward()
    assert float(m.style_proj.weight.grad.abs().sum()) == 0.0  # style always dropped → zeros
    m = tiny()
    opt = torch.optim.Adam(m.parameters(), lr=3e-3)
    torch.manual_seed(1)
    first = np.mean([float(m.training_step(tens)["loss"].detach()) for _ in range(5)])
    for _ in range(150):
        loss = m.training_step(tens)["loss"]
        opt.zero_grad()
        loss.backward()
        opt.step()
    last = np.mean([float(m.training_step(tens)["loss"].detach()) for _ in range(5)])
    assert last < 0.8 * first


def test_packaged_transfer_is_deterministic_and_follows_the_style():
    from mslib.data.datasets import ContentClips, StyleClips
    tr = M.load_mcm_ldm()
    paths = load_builtin(progress=False)
    c = ContentClips(paths["content"], "test", normalize=False)[0]["features"].numpy()
    styles = StyleClips(paths["style"], "test", normalize=False, joints=False)
    s1, s2 = styles[0]["features"].numpy(), styles[len(styles) - 1]["features"].numpy()
    a, b = tr(c, s1, steps=10), tr(c, s1, steps=10)
    assert a.shape == c.shape and np.isfinite(a).all() and np.array_equal(a, b)
    assert not np.allclose(a, tr(c, s2, steps=10), atol=1e-3)
    with pytest.raises(ValueError, match="content_raw"):
        tr(c[:, :10], s1)
