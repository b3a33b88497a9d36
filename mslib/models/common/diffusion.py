"""The diffusion core shared by paper B (MCM-LDM) and paper D (ClusterStyle): a DDPM schedule on any
tensor shape, ε-prediction training, a DDIM sampler, classifier-free guidance and SDEdit noising.

API (stable; `x` is any (B, ...) tensor, `t` integer steps (B,) in [0, T)):
    sched = Schedule(steps=1000, beta_start=0.00085, beta_end=0.012)   # "scaled linear", MLD's (B's and D's)
    sched.betas, sched.alphas_cumprod                                  # (T,) float64 tensors
    x_t = sched.q_sample(x0, t, noise)                                 # forward noising q(x_t | x_0)
    x_t, target = sched.training_pair(x0, t, generator=None)           # ε-prediction: target = ε
    loss = eps_loss(eps_pred, target, mask=None)                       # MSE (masked mean over tokens)
    x0 = sched.predict_x0(x_t, t, eps);  eps = sched.predict_eps(x_t, t, x0)
    t = sched.sample_timesteps(B, generator=None, device="cpu")        # uniform in [0, T)
    eps = cfg_combine(eps_uncond, eps_cond, scale)                     # B Eq. 5: ε_u + s(ε_c − ε_u)
    x0 = ddim_sample(denoiser, shape_or_x_T, sched, n_steps=50, eta=0.0, t_start=None,
                     generator=None, callback=None)
        denoiser(x_t, t) -> ε̂ (same shape as x_t); t is a (B,) long tensor. It is called once per step, so
        guidance that needs several predictions (CFG's branches) batches them inside one call.
        t_start: begin at that step (SDEdit) from the given tensor instead of pure noise.
        callback(i, t, x_t, x0_pred) is called after every step (for pictures of x̂₀ along the way).
    x_t0 = sched.noise_to(x0, t0, generator=None)                      # SDEdit: partial noising to t₀
    ddim_timesteps(n_steps, T, t_start=None) -> the descending integer steps DDIM visits
"""
from __future__ import annotations

from typing import Callable

import torch


class Schedule:
    """DDPM noise schedule: β_t = (linspace(√β₀, √β₁, T))² ("scaled linear", B §3.1), ᾱ_t = Π(1 − β_s)."""

    def __init__(self, steps: int = 1000, beta_start: float = 0.00085, beta_end: float = 0.012):
        if int(steps) < 2:
            raise ValueError(f"steps: need at least 2 diffusion steps, got {steps}")
        if not 0 < beta_start < beta_end < 1:
            raise ValueError(f"beta_start/beta_end: need 0 < beta_start < beta_end < 1, got {beta_start}, {beta_end}")
        self.steps = int(steps)
        self.betas = torch.linspace(beta_start ** 0.5, beta_end ** 0.5, self.steps, dtype=torch.float64) ** 2
        self.alphas_cumprod = torch.cumprod(1.0 - self.betas, 0)  # ᾱ_t, strictly decreasing

    def _abar(self, t, like: torch.Tensor) -> torch.Tensor:
        """ᾱ_t gathered for (B,) steps and shaped to broadcast against `like` (B, ...)."""
        t = torch.as_tensor(t, device=self.alphas_cumprod.device).long().reshape(-1)
        if t.numel() == 1 and like.shape[0] != 1:
            t = t.expand(like.shape[0])
        if t.numel() != like.shape[0]:
            raise ValueError(f"t: expected {like.shape[0]} steps (one per sample), got {t.numel()}")
        if (t < 0).any() or (t >= self.steps).any():
            raise ValueError(f"t: steps must lie in [0, {self.steps}), got min {int(t.min())} max {int(t.max())}")
        a = self.alphas_cumprod[t].to(device=like.device, dtype=like.dtype)
        return a.reshape(-1, *([1] * (like.dim() - 1)))

    def q_sample(self, x0: torch.Tensor, t, noise: torch.Tensor) -> torch.Tensor:
        """Forward noising: x_t = √ᾱ_t x₀ + √(1 − ᾱ_t) ε (B Eq. 1)."""
        if noise.shape != x0.shape:
            raise ValueError(f"noise: shape {tuple(noise.shape)} differs from x0 {tuple(x0.shape)}")
        a = self._abar(t, x0)
        return a.sqrt() * x0 + (1 - a).sqrt() * noise

    def training_pair(self, x0: torch.Tensor, t, generator: torch.Generator | None = None) -> tuple:
        """(x_t, ε): the noisy input and the ε-prediction target (B Eq. 4)."""
        noise = torch.randn(x0.shape, generator=generator, device=x0.device, dtype=x0.dtype)
        return self.q_sample(x0, t, noise), noise

    def sample_timesteps(self, batch: int, generator: torch.Generator | None = None, device="cpu") -> torch.Tensor:
        """(B,) steps drawn uniformly from [0, T)."""
        return torch.randint(0, self.steps, (int(batch),), generator=generator).to(device)

    def predict_x0(self, x_t: torch.Tensor, t, eps: torch.Tensor) -> torch.Tensor:
        """x̂₀ = (x_t − √(1 − ᾱ_t) ε̂) / √ᾱ_t."""
        a = self._abar(t, x_t)
        return (x_t - (1 - a).sqrt() * eps) / a.sqrt()

    def predict_eps(self, x_t: torch.Tensor, t, x0: torch.Tensor) -> torch.Tensor:
        """ε from x_t and x₀: (x_t − √ᾱ_t x₀) / √(1 − ᾱ_t)."""
        a = self._abar(t, x_t)
        return (x_t - a.sqrt() * x0) / (1 - a).sqrt()

    def noise_to(self, x0: torch.Tensor, t0: int, generator: torch.Generator | None = None) -> torch.Tensor:
        """SDEdit partial noising: x_{t₀} ~ q(x_{t₀} | x₀), to denoise from t₀ (ddim_sample(t_start=t₀))."""
        noise = torch.randn(x0.shape, generator=generator, device=x0.device, dtype=x0.dtype)
        return self.q_sample(x0, torch.full((x0.shape[0],), int(t0), dtype=torch.long), noise)


def eps_loss(eps_pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor | None = None) -> torch.Tensor:
    """B Eq. 4: ‖ε − ε̂‖² averaged; `mask` (B, N) True on tokens that count (for (B, N, D) latents)."""
    if eps_pred.shape != target.shape:
        raise ValueError(f"eps_pred: shape {tuple(eps_pred.shape)} differs from target {tuple(target.shape)}")
    err = (eps_pred - target) ** 2
    if mask is None:
        return err.mean()
    w = mask.to(err.dtype).reshape(*mask.shape, *([1] * (err.dim() - mask.dim())))
    return (err * w).sum() / (w.sum() * err[0, 0].numel()).clamp_min(1.0)


def cfg_combine(eps_uncond: torch.Tensor, eps_cond: torch.Tensor, scale: float) -> torch.Tensor:
    """B Eq. 5: classifier-free guidance ε = ε_u + s(ε_c − ε_u); s = 1 is the conditional model, 0 the unconditional."""
    return eps_uncond + float(scale) * (eps_cond - eps_uncond)


def ddim_timesteps(n_steps: int, total: int, t_start: int | None = None) -> list:
    """The descending steps DDIM visits: n_steps evenly spaced in [0, t_start] (t_start default T − 1)."""
    if int(n_steps) < 1:
        raise ValueError(f"n_steps: need at least 1 DDIM step, got {n_steps}")
    top = total - 1 if t_start is None else int(t_start)
    if not 0 <= top < total:
        raise ValueError(f"t_start: must lie in [0, {total}), got {t_start}")
    n = min(int(n_steps), top + 1)
    steps = torch.linspace(top, 0, n).round().long().tolist()
    return sorted(set(steps), reverse=True)


@torch.no_grad()
def ddim_sample(denoiser: Callable, x_T, sched: Schedule, n_steps: int = 50, eta: float = 0.0,
                t_start: int | None = None, generator: torch.Generator | None = None,
                callback: Callable | None = None) -> torch.Tensor:
    """DDIM (Song et al.): x_{t'} = √ᾱ_{t'} x̂₀ + √(1 − ᾱ_{t'} − σ²) ε̂ + σ z, with
    σ = η √((1 − ᾱ_{t'})/(1 − ᾱ_t)) √(1 − ᾱ_t/ᾱ_{t'}); η = 0 is deterministic.

    x_T: a tensor to start from (pure noise, or an SDEdit `noise_to` result with `t_start`), or a shape
    tuple (then pure noise from `generator`). Returns x̂₀ after the last step (t = 0 → x₀ prediction)."""
    if eta < 0:
        raise ValueError(f"eta: must be ≥ 0, got {eta}")
    x = torch.randn(tuple(x_T), generator=generator) if not isinstance(x_T, torch.Tensor) else x_T.clone()
    steps = ddim_timesteps(n_steps, sched.steps, t_start)
    abar = sched.alphas_cumprod
    for i, t in enumerate(steps):
        tt = torch.full((x.shape[0],), t, dtype=torch.long, device=x.device)
        eps = denoiser(x, tt)
        if eps.shape != x.shape:
            raise ValueError(f"denoiser: returned shape {tuple(eps.shape)}, expected {tuple(x.shape)}")
        x0 = sched.predict_x0(x, tt, eps)
        if i + 1 < len(steps):
            a_t, a_prev = float(abar[t]), float(abar[steps[i + 1]])
            sigma = eta * ((1 - a_prev) / (1 - a_t)) ** 0.5 * (1 - a_t / a_prev) ** 0.5
            x = a_prev ** 0.5 * x0 + max(1 - a_prev - sigma ** 2, 0.0) ** 0.5 * eps
            if sigma > 0:
                x = x + sigma * torch.randn(x.shape, generator=generator).to(x)
        else:
            x = x0
        if callback is not None:
            callback(i, t, x, x0)
    return x
