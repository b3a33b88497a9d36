"""Blocks the papers share.

    config.py            one config idiom: paper defaults, `preset("course" | "paper")`, `from_dict`
    layers.py            AdaIN and channel statistics, residual conv blocks, sinusoidal encodings, transformers
    diffusion.py         the noise schedule, DDPM loss, DDIM sampling, classifier-free guidance, SDEdit's start
    vae.py               the motion VAE whose latents B and D diffuse in
    text.py              the small caption encoder (D's text condition, B's style-extractor pre-training)
    style_extractor.py   B's pre-trained style extractor (motion–caption contrastive)
"""
from . import style_extractor, vae

METHODS: dict = {}
TRAINERS = {vae.NAME: vae.run}
