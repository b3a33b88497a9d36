"""The papers' models: shared blocks in `common`, then one package per paper.

    common/        config idiom, layers, diffusion, the motion VAE, the text encoder, B's style extractor
    adain/         paper A: stage 1 AdaIN transfer, stage 2 DSDN
    mcm_ldm/       paper B: MCM-LDM          contrastive/   paper C          clusterstyle/  paper D
    registry.py    the benchmark's methods and the CLI's trainers, read from each package's METHODS and TRAINERS
"""
