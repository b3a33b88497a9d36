"""Paper A: AdaIN style transfer with dual-path training (stage 1) and the Dual-Stream Denoising Network (stage 2).

    model.py     stage 1: content/style encoders, AdaIN (A Eq. 2), decoder, the dual-path losses (A Eq. 3–5)
    dsdn.py      stage 2: LSTM and conv streams, the Adaptive Gating Fusion Unit (A Eq. 6–12)
    train.py     both training recipes           transfer.py   the packaged models at inference
"""
from .dsdn import DSDN, MODES, DsdnConfig, evaluate_pairs
from .model import ROOT_DIMS, AdainConfig, AdainTransfer, pose_positions
from .train import (ADAIN_TRAINING, DSDN_TRAINING, TransferPairs, neutral_pairs, run_adain, run_dsdn,
                    train_adain, train_dsdn)
from .transfer import adain_dsdn_method, adain_method, load_adain, load_dsdn

METHODS = {
    "adain": (adain_method, "A stage 1: AdaIN transfer (content root path kept, decoder's stylized pose)"),
    "adain+dsdn": (adain_dsdn_method, "A stages 1+2: AdaIN transfer, then the dual-stream correction"),
}
TRAINERS = {"adain": run_adain, "dsdn": run_dsdn}
