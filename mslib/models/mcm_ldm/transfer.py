"""Paper B at inference (B §3.3): the content clip gives f_c and f_t, the style clip f_s; DDIM with
classifier-free guidance (B Eq. 5) from noise; the VAE decodes. The packaged model and the benchmark's method.

Clips longer than the VAE's `max_len` rows are transferred in independent chunks of `max_len` rows (the
VAE encodes at most that many); every chunk starts from the same seeded noise.
"""
from __future__ import annotations

import numpy as np
import torch

from ...checkpoints import course_path, load_state, read_checkpoint
from ...motion.features import N_FEATURES, TRAJECTORY_DIMS
from ..common import style_extractor as SE
from ..common.vae import MotionVAE, load_vae
from .model import MCMLDM, NAME


class Transfer:
    """Content + style raw features → stylised raw features, by DDIM with CFG from the content's conditions."""

    def __init__(self, model: MCMLDM, vae: MotionVAE, extractor, device="cpu"):
        self.model, self.vae, self.extractor, self.device = model.eval(), vae.eval(), extractor, torch.device(device)

    def _norm(self, raw) -> torch.Tensor:
        return self.vae.normalize(torch.as_tensor(np.asarray(raw), dtype=torch.float32, device=self.device))

    @torch.no_grad()
    def style_embedding(self, style_raw) -> torch.Tensor:
        """(1, S) style embedding f_s of a raw style clip (pre-trained extractor, or the model's own in the ablation)."""
        s = self._norm(style_raw)[None, : self.vae.cfg.max_len]
        enc = self.model.style_net if self.model.style_net is not None else self.extractor
        return enc(s)

    @torch.no_grad()
    def conditions(self, content_raw, style_raw) -> tuple:
        """(cond dict, null style, length) for one content clip of ≤ max_len rows."""
        x = self._norm(content_raw)[None]  # (1, T, N_FEATURES)
        xc = x.clone()
        xc[..., TRAJECTORY_DIMS] = 0.0  # the content condition sees no trajectory
        zc = self.vae.encode(xc)  # (1, N, d)
        mask = torch.ones(1, x.shape[1], dtype=torch.bool, device=self.device)
        style = self.style_embedding(style_raw)
        cond = self.model.conditions(zc, style, x[..., TRAJECTORY_DIMS], mask)  # B Eq. 1
        null = self.model.style_proj(torch.zeros_like(style))  # the projected null style ∅
        return cond, null, x.shape[1]

    @torch.inference_mode()
    def __call__(self, content_raw, style_raw, scale: float | None = None, steps: int | None = None,
                 seed: int = 0, copy_traj: bool = False, callback=None) -> np.ndarray:
        """(T, N_FEATURES) raw content, (S, N_FEATURES) raw style → (T, N_FEATURES) raw output; `copy_traj`
        pastes the content's root velocities over the generated ones (the "copied trajectory" baseline)."""
        content_raw = np.asarray(content_raw, np.float64)
        if content_raw.ndim != 2 or content_raw.shape[1] != N_FEATURES or len(content_raw) < 2:
            raise ValueError(f"content_raw: expected (T, {N_FEATURES}) features with T ≥ 2, got {content_raw.shape}")
        L = self.vae.cfg.max_len
        pieces = []
        for start in range(0, len(content_raw), L):  # longer clips: independent chunks of max_len rows
            chunk = content_raw[start:start + L]
            cond, null, T = self.conditions(chunk, style_raw)
            g = torch.Generator().manual_seed(int(seed))
            z = self.model.sample(cond, null, (1, self.model.n, self.model.d), scale, steps, g, callback)
            out = self.vae.decode_raw(z, [T])[0]
            if copy_traj:
                out[:, TRAJECTORY_DIMS] = chunk[:, TRAJECTORY_DIMS]
            pieces.append(out)
        return np.concatenate(pieces)


def load_mcm_ldm(path=None, device="cpu", vae_path=None, style_path=None) -> Transfer:
    """The transfer function of a checkpoint (default: the packaged course ones)."""
    path = course_path(NAME) if path is None else path
    model = MCMLDM.from_config(read_checkpoint(path, NAME)["config"])
    load_state(path, model, NAME)
    vae = load_vae(vae_path, device)
    extractor = SE.load_style_extractor(style_path, device) if model.style_net is None else None
    return Transfer(model.to(device), vae, extractor, device)


def mcm_ldm_method(device="cpu"):
    """transfer(content, style) → stylized features with the course checkpoints."""
    tr = load_mcm_ldm(device=device)

    def transfer(content, style):
        return tr(content["features"], style["features"])
    # every parameter used at inference: denoiser, VAE, frozen style extractor
    transfer.n_parameters = sum(p.numel() for m in (tr.model, tr.vae, tr.extractor) if m is not None
                                for p in m.parameters())
    return transfer
