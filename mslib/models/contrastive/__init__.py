"""Paper C: self-supervised contrastive disentanglement of content and style.

    model.py     E_c, E_s, the AdaIN generator, the MLP discriminator and the losses (C Eq. 1–5)
    data.py      unlabelled (target, source) training pairs
    train.py     the training recipe           transfer.py   the packaged model at inference
"""
from .data import PairedClips
from .model import (NAME, ContrastiveConfig, ContrastiveModel, adversarial_losses, info_nce, reconstruction_loss,
                    recording_nce, triplet_loss)
from .train import run, train
from .transfer import contrastive_method, interpolate_styles, load

METHODS = {NAME: (contrastive_method, "paper C: content code + AdaIN from a style code, InfoNCE + triplet, no labels")}
TRAINERS = {NAME: run}
