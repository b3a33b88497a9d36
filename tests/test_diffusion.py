"""Diffusion core against closed forms: schedule, forward noising, ε target, DDIM, CFG, SDEdit."""
import pytest
import torch

from mslib.models.common.diffusion import Schedule, cfg_combine, ddim_sample, ddim_timesteps, eps_loss


def test_scaled_linear_schedule_endpoints_and_decreasing_abar():
    s = Schedule()
    assert s.betas.shape == (1000,)
    assert abs(float(s.betas[0]) - 0.00085) < 1e-12 and abs(float(s.betas[-1]) - 0.012) < 1e-12
    mid = ((0.00085 ** 0.5 + 0.012 ** 0.5) / 2) ** 2  # the square of the midpoint of the √β line
    assert abs(float(s.betas[499:501].mean()) - mid) < 1e-6
    a = s.alphas_cumprod
    assert bool((a[1:] < a[:-1]).all()) and 0 < float(a[-1]) < 0.01 and float(a[0]) > 0.999


def test_forward_noising_mean_and_variance():
    s = Schedule()
    g = torch.Generator().manual_seed(0)
    x0 = torch.full((20000, 3), 2.0)
    for t in (10, 400, 999):
        xt, eps = s.training_pair(x0, torch.full((20000,), t), generator=g)
        a = float(s.alphas_cumprod[t])
        assert abs(float(xt.mean()) - a ** 0.5 * 2.0) < 0.02
        assert abs(float(xt.var()) - (1 - a)) < 0.03 * max(1 - a, 0.05)
        assert torch.allclose(s.predict_x0(xt, torch.full((20000,), t), eps), x0, atol=1e-4)


def test_predict_eps_inverts_q_sample():
    s = Schedule()
    x0, n = torch.randn(4, 7, 5), torch.randn(4, 7, 5)
    t = torch.tensor([0, 5, 500, 999])
    xt = s.q_sample(x0, t, n)
    assert torch.allclose(s.predict_eps(xt, t, x0), n, atol=1e-4)


def test_ddim_with_true_noise_recovers_x0_exactly_and_is_deterministic():
    s = Schedule()
    g = torch.Generator().manual_seed(1)
    x0, noise = torch.randn(3, 4, 6, generator=g), torch.randn(3, 4, 6, generator=g)
    xT = s.q_sample(x0, torch.full((3,), 999), noise)
    oracle = lambda x, t: noise  # the exact ε at every step of an η = 0 path
    for n_steps in (1, 10, 50):
        out = ddim_sample(oracle, xT, s, n_steps=n_steps, eta=0.0)
        assert torch.allclose(out, x0, atol=1e-4)
    net = lambda x, t: torch.tanh(x) * (t.float()[:, None, None] / 1000)
    a = ddim_sample(net, xT, s, n_steps=20)
    b = ddim_sample(net, xT, s, n_steps=20)
    assert torch.equal(a, b)
    c = ddim_sample(net, xT, s, n_steps=20, eta=1.0, generator=torch.Generator().manual_seed(3))
    assert not torch.allclose(a, c)


def test_sdedit_partial_noising_starts_at_t0():
    s = Schedule()
    assert ddim_timesteps(50, 1000)[0] == 999 and ddim_timesteps(50, 1000)[-1] == 0
    steps = ddim_timesteps(10, 1000, t_start=580)
    assert steps[0] == 580 and steps[-1] == 0 and len(steps) == 10
    x0, noise = torch.randn(2, 3, 4), torch.randn(2, 3, 4)
    x = s.q_sample(x0, torch.full((2,), 580), noise)
    seen = []
    out = ddim_sample(lambda x, t: noise, x, s, n_steps=10, t_start=580, callback=lambda i, t, xt, x0p: seen.append(t))
    assert seen[0] == 580 and torch.allclose(out, x0, atol=1e-4)
    xn = s.noise_to(torch.zeros(5000, 2), 580, generator=torch.Generator().manual_seed(0))
    assert abs(float(xn.var()) - (1 - float(s.alphas_cumprod[580]))) < 0.05


def test_ddim_calls_the_denoiser_once_per_visited_step():
    calls = []

    def denoiser(x, t):
        calls.append(int(t[0]))
        return torch.zeros_like(x)
    ddim_sample(denoiser, torch.zeros(2, 3), Schedule(), n_steps=20, t_start=600)
    assert calls == ddim_timesteps(20, 1000, t_start=600) and len(calls) == 20


def test_cfg_scale_one_is_conditional_zero_unconditional():
    u, c = torch.randn(2, 3), torch.randn(2, 3)
    assert torch.allclose(cfg_combine(u, c, 1.0), c)
    assert torch.allclose(cfg_combine(u, c, 0.0), u)
    assert torch.allclose(cfg_combine(u, c, 2.5), u + 2.5 * (c - u))


def test_eps_loss_masks_tokens_and_bad_input():
    p, t = torch.zeros(2, 3, 4), torch.ones(2, 3, 4)
    p[:, 2] = 5.0  # a padded token with a large error
    mask = torch.tensor([[True, True, False], [True, True, False]])
    assert abs(float(eps_loss(p, t, mask)) - 1.0) < 1e-6
    assert float(eps_loss(p, t)) > 1.0
    with pytest.raises(ValueError, match="t:"):
        Schedule().q_sample(torch.zeros(2, 3), torch.tensor([0, 1000]), torch.zeros(2, 3))
    with pytest.raises(ValueError, match="steps"):
        Schedule(steps=1)
