"""Paper B at inference: DDIM with classifier-free guidance from the content's conditions, the packaged model, the benchmark's method."""
from __future__ import annotations

import numpy as np
import torch

from ...checkpoints import course_path, load_state, read_checkpoint
from ..common import style_extractor as SE
from ..common.vae import MotionVAE, load_vae
from .model import MCMLDM, NAME, TRAJ, MCMConfig

# ---------------------------------------------------------------- transfer
class Transfer:
    """Content + style raw features → stylised raw features, by DDIM with CFG from the content's conditions."""

    def __init__(self, model: MCMLDM, vae: MotionVAE, extractor, device="cpu"):
        self.model, self.vae, self.extractor, self.device = model.eval(), vae.eval(), extractor, torch.device(device)

    def _norm(self, raw) -> torch.Tensor:
        return self.vae.normalize(torch.as_tensor(np.asarray(raw), dtype=torch.float32, device=self.device))

    @torch.no_grad()
    def style_embedding(self, style_raw) -> torch.Tensor:
        """(1, S) style embedding of a raw style clip (pre-trained extractor, or the model's own in the ablation)."""
        s = self._norm(style_raw)[None, : self.vae.cfg.max_len]
        enc = self.model.style_net if self.model.style_net is not None else self.extractor
        return enc(s)

    @torch.no_grad()
    def conditions(self, content_raw, style_raw) -> tuple:
        """(cond dict, null style, length) for one content clip of ≤ max_len rows."""
        x = self._norm(content_raw)[None]  # (1, T, 263)
        xc = x.clone()
        xc[..., TRAJ] = 0.0
        zc = self.vae.encode(xc)
        mask = torch.ones(1, x.shape[1], dtype=torch.bool, device=self.device)
        style = self.style_embedding(style_raw)
        cond = self.model.conditions(zc, style, x[..., TRAJ], mask)
        null = self.model.style_proj(torch.zeros_like(style))  # the projected null style
        return cond, null, x.shape[1]

    @torch.no_grad()
    def __call__(self, content_raw, style_raw, scale: float | None = None, steps: int | None = None,
                 seed: int = 0, copy_traj: bool = False, callback=None) -> np.ndarray:
        """(T, 263) raw content, (S, 263) raw style → (T, 263) raw output; `copy_traj` pastes the content's
        root velocities over the generated ones (the "copied trajectory" baseline)."""
        content_raw = np.asarray(content_raw, np.float64)
        if content_raw.ndim != 2 or content_raw.shape[1] != 263 or len(content_raw) < 2:
            raise ValueError(f"content_raw: expected (T, 263) features with T ≥ 2, got {content_raw.shape}")
        L = self.vae.cfg.max_len
        pieces = []
        for start in range(0, len(content_raw), L):  # longer clips: independent chunks of max_len rows
            chunk = content_raw[start:start + L]
            cond, null, T = self.conditions(chunk, style_raw)
            g = torch.Generator().manual_seed(int(seed))
            z = self.model.sample(cond, null, (1, self.model.n, self.model.d), scale, steps, g, callback)
            out = self.vae.decode_raw(z, [T])[0]
            if copy_traj:
                out[:, TRAJ] = chunk[:, TRAJ]
            pieces.append(out)
        return np.concatenate(pieces)


def load_mcm_ldm(path=None, device="cpu", vae_path=None, style_path=None) -> Transfer:
    """The transfer function of a checkpoint (default: the packaged course ones)."""
    path = course_path(NAME) if path is None else path
    blob = read_checkpoint(path, NAME)
    c = blob["config"]
    model = MCMLDM(MCMConfig.from_dict(c), c["latent_tokens"], c["latent_dim"], c["style_dim"], c.get("style_cfg"))
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
