"""Paper B: MCM-LDM, motion latent diffusion with content, trajectory and style conditions.

    model.py     the config, the denoiser (content concatenated, style and trajectory by AdaLN-Zero), the
                 StyleRemover, the trajectory encoder, the training step and the DDIM sampler with CFG
    train.py     the training recipe on frozen VAE latents and style embeddings
    transfer.py  the packaged model at inference: clip → conditions → DDIM with CFG → VAE decoder
B's style extractor and the motion VAE are shared blocks (`mslib.models.common`).
"""
from ..common import style_extractor as _style_extractor
from .model import MCMLDM, NAME, STYLE_WINDOW, Block, MCMConfig, StyleRemover, TrajectoryEncoder, auto_patch, patchify
from .train import TensorSet, build_tensors, prepare, run, train_mcm
from .transfer import Transfer, load_mcm_ldm, mcm_ldm_method

_COURSE = MCMConfig.preset("course")
METHODS = {NAME: (mcm_ldm_method, "B: latent diffusion with content/style/trajectory conditions, DDIM and CFG "
                                  f"({_COURSE.ddim_steps} steps and λ = {_COURSE.cfg_scale:g} in the course preset)")}
TRAINERS = {NAME: run, _style_extractor.NAME: _style_extractor.run}
