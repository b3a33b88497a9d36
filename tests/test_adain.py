"""Paper A stage 1 (AdaIN transfer): shapes, the statistics AdaIN moves, the two paths, the root
trajectory kept, a tiny training run, the packaged checkpoint, and the bench bar."""
import numpy as np
import pytest
import torch

from mslib.checkpoints import course_path
from mslib.models import adain as A
from mslib.models.common.layers import adain, channel_stats
from mslib.motion.features import decode, encode
from mslib.training import TrainConfig

TINY = A.AdainConfig.preset("course", hidden=16, content_blocks=1, decoder_blocks=1, style_layers=1, heads=2,
                            clip_frames=24, pretrain_steps=10)
TINY_SEPARATE = A.AdainConfig.from_dict({**TINY.to_dict(), "shared_encoder": False, "pretrain_steps": 0})


def _model(seed=0, cfg=TINY):
    torch.manual_seed(seed)
    return A.AdainTransfer(cfg, np.zeros(263), np.ones(263))


def _features(n=40, seed=0):
    from mslib.data.synth import generate_clip
    return encode(generate_clip("walk", "neutral", seed=seed, index=0).positions)[:n].astype(np.float64)


@pytest.mark.parametrize("cfg", [TINY, TINY_SEPARATE], ids=["shared", "separate"])
def test_shapes_and_root_path_from_the_content(cfg):
    m = _model(cfg=cfg)
    c, s = _features(40), _features(31, seed=1)
    out = m.transfer_features(c, s)
    assert out.shape == c.shape
    np.testing.assert_allclose(out[:, :4], c[:, :4], atol=1e-5)  # dims 0..3 are the content's
    pos = m.transfer(c, s)
    assert pos.shape == (40, 22, 3)  # decode: one frame per feature row (recover_from_ric)
    np.testing.assert_allclose(pos[:, 0, [0, 2]], decode(c)[:, 0, [0, 2]], atol=1e-4)


def test_pose_positions_match_decoded_joints_relative_to_the_root():
    f = torch.as_tensor(_features(30), dtype=torch.float32)
    p = A.pose_positions(f[None])[0]
    assert p.shape == (30, 22, 3)
    # frame 0 faces +Z with the root at the origin in XZ: decoded joints there equal the pose positions
    np.testing.assert_allclose(p[0].numpy(), decode(f.double().numpy())[0], atol=1e-5)


@pytest.mark.parametrize("cfg", [TINY, TINY_SEPARATE], ids=["shared", "separate"])
def test_adain_switches_move_the_stylized_code_statistics(cfg):
    m = _model(cfg=cfg)
    x = torch.randn(2, 30, 263)
    s = torch.randn(2, 31, 263)
    code = m.content_code(x)
    mu_s, sig_s = m.style_stats(s)
    mu_c, sig_c = channel_stats(code)
    for use_mean, use_std, want_mu, want_sig in ((True, True, mu_s, sig_s), (True, False, mu_s, sig_c),
                                                 (False, True, mu_c, sig_s)):
        got_mu, got_sig = channel_stats(adain(code, mu_s, sig_s, use_mean=use_mean, use_std=use_std))
        assert torch.allclose(got_mu, want_mu, atol=1e-4) and torch.allclose(got_sig, want_sig, atol=1e-3)
    full = m(x, s)
    mean_only = m(x, s, use_std=False)
    assert not torch.allclose(full, mean_only)


def test_shared_encoder_reads_style_statistics_in_the_content_code_space():
    m = _model()
    assert m.style_encoder is None
    f = torch.as_tensor(_features(30), dtype=torch.float32)[None]
    mu, sig = m.style_stats(f)
    want_mu, want_sig = channel_stats(m.content_code(m.normalize(f)))  # the same channels AdaIN moves
    assert torch.allclose(mu, want_mu) and torch.allclose(sig, want_sig)
    # a motion with its own statistics is (up to AdaIN's ε) the plain autoencoder: AdaIN is the identity
    x = m.normalize(f)
    own = m.stylize(x, mu, sig)
    plain = m.denormalize(m.decoder(m.content_code(x)))
    assert torch.allclose(own[..., 4:], plain[..., 4:], atol=1e-3)
    separate = _model(cfg=TINY_SEPARATE)
    assert isinstance(separate.style_encoder, A.model.StyleEncoder)
    # separate E_s: the content code ignores the content's mean over time (its level comes from AdaIN)
    assert torch.allclose(separate.content_code(x + 1.0), separate.content_code(x), atol=1e-5)


def test_config_presets_and_stored_configs():
    assert A.AdainConfig() == A.AdainConfig.preset("paper")  # the defaults are A's
    course = A.AdainConfig.preset("course")
    assert course.shared_encoder and course.hidden == 64 and not A.AdainConfig().shared_encoder
    assert A.AdainConfig.preset("course", hidden=8).hidden == 8
    assert A.AdainTransfer(TINY.to_dict()).style_encoder is None  # a stored config builds the same model
    assert isinstance(A.AdainTransfer(TINY_SEPARATE.to_dict()).style_encoder, A.model.StyleEncoder)
    with pytest.raises(ValueError, match="hiden"):
        A.AdainConfig.preset("course", hiden=8)
    with pytest.raises(ValueError, match="preset"):
        A.AdainConfig.preset("laptop")
    # a retired research option loads when it holds the value the library always uses, else is refused
    assert A.AdainTransfer({**TINY.to_dict(), "content_skip": False}).cfg == TINY
    with pytest.raises(ValueError, match="content_skip"):
        A.AdainTransfer({**TINY.to_dict(), "content_skip": True})


def test_pretraining_optimises_reconstruction_only():
    m = _model()
    batch = {"content": {"features": torch.randn(3, 24, 263)}, "style": {"features": torch.randn(3, 31, 263)}}
    m.pretraining = True
    logs = m.losses(batch)
    assert torch.isclose(logs["loss"], 0.5 * (logs["content"] + logs["style_rec"]))
    assert float(logs["style"].detach()) > 0  # still measured and logged


def test_losses_are_the_two_paths():
    m = _model()
    batch = {"content": {"features": torch.randn(3, 24, 263)}, "style": {"features": torch.randn(3, 31, 263)}}
    logs = m.losses(batch)
    assert set(logs) == {"loss", "content", "style", "style_rec"}
    # A Eq. 5, with the workbook's extra reconstruction of the style clips averaged into the content term
    assert torch.isclose(logs["loss"], TINY.lambda_style * logs["style"]
                         + TINY.lambda_content * 0.5 * (logs["content"] + logs["style_rec"]))
    torch.manual_seed(0)
    plain = A.AdainTransfer(A.AdainConfig.from_dict({**TINY.to_dict(), "style_recon": False}), np.zeros(263), np.ones(263))
    p_logs = plain.losses(batch)
    assert set(p_logs) == {"loss", "content", "style"}
    assert torch.isclose(p_logs["loss"], TINY.lambda_style * p_logs["style"] + TINY.lambda_content * p_logs["content"])
    # the self-reconstruction path does not see the style clip
    batch2 = {"content": batch["content"], "style": {"features": torch.randn(3, 31, 263)}}
    assert torch.isclose(m.losses(batch2)["content"], logs["content"])
    assert not torch.isclose(m.losses(batch2)["style"], logs["style"])


def test_bad_input_names_the_argument():
    m = _model()
    with pytest.raises(ValueError, match="content_features"):
        m.transfer_features(np.zeros((10, 7)), _features(31))
    with pytest.raises(ValueError, match="preset"):
        A.train_adain("huge", "x", "y")


def test_tiny_training_lowers_both_losses(tmp_path):
    from mslib.data.corpora import load_builtin
    p = load_builtin(progress=False)
    tcfg = TrainConfig(steps=30, batch_size=8, lr=3e-3, val_every=30, val_batches=1)
    model, h = A.train_adain("course", p["content"], p["style"], seed=0, out=tmp_path / "a.pt", progress=False,
                             config=A.AdainConfig.from_dict({**TINY.to_dict(), "pretrain_steps": 30}), train_config=tcfg)
    pre = model.pretrain_history  # the autoencoder steps came first
    assert pre["step"][-1] == 30 and np.mean(pre["train"]["content"][-5:]) < np.mean(pre["train"]["content"][:5])
    assert not any(q.requires_grad for q in model.content_encoder.parameters())  # E frozen: A Eq. 3's loss network
    assert all(q.requires_grad for q in model.decoder.parameters())
    first, last = np.mean(h["train"]["style"][:3]), np.mean(h["train"]["style"][-3:])
    assert last < first
    assert set(h["val"]) >= {"content", "style", "loss"}
    again = A.load_adain(tmp_path / "a.pt")
    c, s = _features(20), _features(31, seed=2)
    np.testing.assert_allclose(again.transfer_features(c, s), model.transfer_features(c, s), atol=1e-5)


@pytest.mark.skipif(not course_path("adain").is_file(), reason="course checkpoint not trained yet")
def test_course_checkpoint_bars():
    from mslib.checkpoints import read_checkpoint
    blob = read_checkpoint(course_path("adain"), "adain")
    h = blob["extra"]["history"]
    train = np.mean(h["train"]["content"][-50:])
    assert h["val"]["content"][-1] <= 1.25 * train  # validation content loss within 25% of training
    assert course_path("adain").stat().st_size <= 4 * 2**20
