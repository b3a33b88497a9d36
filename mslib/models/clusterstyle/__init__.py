"""Paper D: ClusterStyle, style prototypes for intra-style diversity, a text-to-motion denoiser with the SMA.

    prototypes.py  the style encoder and its prototype banks: Sinkhorn assignment, EMA, InfoNCE (D §3.2–3.3)
    model.py       the latent denoiser with the Stylistic Modulation Adapter (D §3.1, §3.4)
    train.py       the three training stages (style model, text-to-motion, SMA)
    transfer.py    three-way classifier-free guidance, prototype guidance, generation and SDEdit transfer
"""
from .model import NAME, SMA, STYLE_NAME, T2M_NAME, ClusterStyle, ClusterStyleConfig, load_clusterstyle, null_text
from .prototypes import (PrototypeConfig, PrototypeStyleModel, load_style_model, matched_purity, sinkhorn,
                         substyle_confusion)
from .train import content_caption, run_sma, run_style, run_t2m, train_style_model
from .transfer import Pipeline, clusterstyle_method, load_pipeline, pose_diversity

METHODS = {NAME: (clusterstyle_method, "D: SDEdit transfer (t0=600, 20 DDIM steps), text CFG, reference-feature "
                                       "guidance for t < 300")}
TRAINERS = {STYLE_NAME: run_style, T2M_NAME: run_t2m, NAME: run_sma}
