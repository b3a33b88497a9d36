"""Paper A stage 2 (DSDN): stream shapes, the gate, the three ablation modes, the losses, the root path
kept, a tiny training run with a checkpoint round trip, neutral training pairs, and the packaged checkpoint."""
import numpy as np
import pytest
import torch

from mslib.checkpoints import course_path
from mslib.models import adain as A
from mslib.models import adain as D
from mslib.motion.features import encode
from mslib.training import TrainConfig


def _model(mode="dual", seed=0, **kw):
    torch.manual_seed(seed)
    return D.DSDN(D.DsdnConfig.preset("course", mode=mode, static_channels=(32, 64), lstm_hidden=16, regressor_hidden=16,
                               gate_hidden=8, **kw))


def _features(n=40, seed=0):
    from mslib.data.synth import generate_clip
    return encode(generate_clip("walk", "neutral", seed=seed, index=0).positions)[:n].astype(np.float64)


@pytest.mark.parametrize("T", [32, 37, 5])
def test_streams_keep_the_shape_and_the_static_code_is_a_quarter_long(T):
    m = _model()
    x = torch.randn(2, T, 263)
    assert m.dynamic(x).shape == (2, T, 263)
    assert m.static(x).shape == (2, T, 263)
    code = m.static.encoder(torch.randn(2, 263, 32))
    assert code.shape == (2, 64, 8)  # C_s at T/4 (A §3.3.4)
    out, alpha = m(x, return_gate=True)
    assert out.shape == (2, T, 263) and alpha.shape == (2, T, 1)
    assert (alpha > 0).all()  # Softplus (A Eq. 10)


def test_dual_output_is_the_gated_mix_of_the_two_streams():
    m = _model()
    x = torch.randn(3, 16, 263)
    out, alpha = m(x, return_gate=True)
    want = alpha * m.dynamic(x) + (1 - alpha) * m.static(x)
    assert torch.allclose(out, want, atol=1e-6)
    # A Eq. 8-10 by hand
    h = torch.tanh(x @ m.gate.w1.weight.T + m.gate.w1.bias)
    assert torch.allclose(alpha, torch.log1p(torch.exp(h @ m.gate.w2.weight.T + m.gate.w2.bias)), atol=1e-6)


def test_ablation_modes_hold_only_their_stream():
    dyn, sta = _model("dynamic"), _model("static")
    assert dyn.static is None and dyn.gate is None and dyn.dynamic is not None
    assert sta.dynamic is None and sta.gate is None and sta.static is not None
    x = torch.randn(1, 12, 263)
    assert torch.allclose(dyn(x), dyn.dynamic(x)) and torch.allclose(sta(x), sta.static(x))
    with pytest.raises(ValueError, match="mode"):
        _model("triple")


def test_losses_rec_and_vel():
    m = _model(lambda_vel=0.5)
    noisy, clean = torch.randn(2, 16, 263), torch.randn(2, 16, 263)
    logs = m.losses((noisy, clean))
    fused = m(noisy)
    assert torch.isclose(logs["rec"], (fused - clean).abs().mean())  # A Eq. 11
    assert torch.isclose(logs["vel"], (fused[:, 1:] - fused[:, :-1]).abs().mean())  # A Eq. 12
    assert torch.isclose(logs["loss"], logs["rec"] + 0.5 * logs["vel"])
    # a constant-in-time output has no velocity loss
    const = torch.zeros(1, 8, 263)
    assert float((const[:, 1:] - const[:, :-1]).abs().mean()) == 0.0


def test_correct_features_keeps_the_root_path_and_the_length():
    m = _model()
    f = _features(37)
    out = m.correct_features(f)
    assert out.shape == f.shape
    np.testing.assert_allclose(out[:, :4], f[:, :4], atol=1e-5)
    assert m.gate_weights(f).shape == (37,)
    with pytest.raises(ValueError, match="features"):
        m.correct_features(np.zeros((10, 5)))


def test_correction_strength_moves_linearly_from_the_input_to_the_full_correction():
    m = _model()
    f = _features(33)
    full, none, half = (m.correct_features(f, strength=k) for k in (1.0, 0.0, 0.5))
    np.testing.assert_allclose(none, f, atol=1e-4)  # κ = 0: stage 2 off
    np.testing.assert_allclose(half, 0.5 * (f + full), atol=1e-4)
    assert np.abs(full - f)[:, 4:].max() > 1e-2  # the untrained network does change the motion
    np.testing.assert_allclose(m.correct_features(f), m.correct_features(f, strength=m.cfg.correction_strength))
    assert D.DsdnConfig.preset("paper").correction_strength == 1.0  # A's full correction


def test_a_stored_config_builds_the_same_model_and_unknown_keys_are_refused():
    m = _model()
    assert D.DSDN(m.config).cfg == m.cfg  # static_channels comes back as a tuple from the stored list
    with pytest.raises(ValueError, match="gate_hiden"):
        D.DSDN({**m.config, "gate_hiden": 8})


def test_tiny_training_lowers_rec_and_the_checkpoint_round_trips(tmp_path):
    torch.manual_seed(0)
    clean = torch.randn(16, 16, 263).cumsum(1) * 0.1
    noisy = clean + 0.3 * torch.randn_like(clean)
    data = ((noisy[:12], clean[:12]), (noisy[12:], clean[12:]))
    cfg = D.DsdnConfig.preset("course", static_channels=(32, 64), lstm_hidden=16, regressor_hidden=16, gate_hidden=8, clip_frames=16)
    tcfg = TrainConfig(steps=60, batch_size=4, lr=3e-3, val_every=30, val_batches=1)
    stage1 = A.AdainTransfer(A.AdainConfig(hidden=8, content_blocks=1, decoder_blocks=1, heads=2))
    model, h = D.train_dsdn("course", None, None, out=tmp_path / "d.pt", progress=False, config=cfg,
                            train_config=tcfg, stage1=stage1, data=data)
    assert np.mean(h["train"]["rec"][-5:]) < np.mean(h["train"]["rec"][:5])
    again = D.load_dsdn(tmp_path / "d.pt")
    f = _features(20)
    np.testing.assert_allclose(again.correct_features(f), model.correct_features(f), atol=1e-5)


def test_neutral_pairs_are_content_clips_and_their_neutral_transfers():
    from mslib.data.corpora import load_builtin
    p = load_builtin(progress=False)
    torch.manual_seed(0)
    stage1 = A.AdainTransfer(A.AdainConfig(hidden=8, content_blocks=1, decoder_blocks=1, heads=2))
    noisy, clean = D.neutral_pairs(stage1, p["content"], p["style"], "val", 16)
    assert noisy.shape == clean.shape and noisy.shape[1:] == (16, 263)
    # the transfer keeps the content's root path (dims 0..3), so those columns agree exactly
    assert torch.allclose(noisy[..., :4], clean[..., :4], atol=1e-4)
    assert not torch.allclose(noisy[..., 4:], clean[..., 4:])


def test_bad_preset_is_a_clear_error():
    with pytest.raises(ValueError, match="preset"):
        D.train_dsdn("huge", "x", "y")


@pytest.mark.skipif(not course_path("dsdn").is_file(), reason="course checkpoint not trained yet")
def test_course_checkpoint_loads_and_is_small():
    m = D.load_dsdn()
    assert m.cfg.mode == "dual"
    assert course_path("dsdn").stat().st_size <= 8 * 2**20
    f = _features(30)
    assert np.isfinite(m.correct_features(f)).all()


@pytest.mark.skipif(not (course_path("dsdn").is_file() and course_path("adain").is_file()),
                    reason="course checkpoints not trained yet")
def test_stage_two_smooths_the_transfers_and_slides_the_feet_less():
    from mslib.evaluation.bench import get_method, load_pairs, positions
    from mslib.evaluation.metrics import foot_slide_fsf, jitter
    pairs = load_pairs(0, 40)
    outs = {m: [positions(get_method(m)(c, s)) for c, s in pairs] for m in ("adain", "adain+dsdn")}
    jit = {m: np.mean([jitter(o) for o in v]) for m, v in outs.items()}
    fsf = {m: np.mean([foot_slide_fsf(o) for o in v]) for m, v in outs.items()}
    assert jit["adain+dsdn"] < jit["adain"] and fsf["adain+dsdn"] < fsf["adain"]
