"""Motion VAE: shapes, masking, learning on a few clips, the packaged checkpoint's reconstruction."""
import numpy as np
import pytest
import torch

from mslib.checkpoints import course_path
from mslib.data.corpora import load_builtin
from mslib.models.common import vae as V
from mslib.models.common.layers import pad_batch


def tiny(**kw):
    cfg = V.VAEConfig(latent_tokens=3, latent_dim=8, dim=32, heads=2, layers=1, ff_mult=2, dropout=0.0,
                      max_len=64, min_len=8)
    for k, v in kw.items():
        setattr(cfg, k, v)
    return V.MotionVAE(cfg)


def tiny_conv():
    return V.MotionVAE(V.VAEConfig(arch="conv", latent_tokens=16, latent_dim=4, dim=16, layers=3, max_len=64,
                                   min_len=8, down=4))


@pytest.mark.parametrize("make, latent", [(tiny, (3, 8)), (tiny_conv, (16, 4))], ids=["transformer", "conv"])
def test_shapes_and_padding_invariance(make, latent):
    torch.manual_seed(0)
    vae = make().eval()
    a, b = torch.randn(21, 263), torch.randn(40, 263)
    x, mask = pad_batch([a, b])
    z = vae.encode(x, mask)
    assert z.shape == (2, *latent)  # conv: max_len / 4 tokens whatever the clip's length
    alone = vae.encode(a[None])
    assert torch.allclose(z[:1], alone, atol=1e-5)  # the padded frames of the batch change nothing
    out = vae.decode(z, torch.tensor([21, 40]))
    assert out.shape == (2, 40, 263)
    assert torch.allclose(out[:1, :21], vae.decode(alone, [21]), atol=1e-5)


def test_bad_input_names_the_argument():
    vae = tiny()
    with pytest.raises(ValueError, match="x:"):
        vae.encode(torch.zeros(1, 10, 12))
    with pytest.raises(ValueError, match="x:"):
        vae.encode(torch.zeros(1, 65, 263))
    with pytest.raises(ValueError, match="lengths:"):
        vae.decode(torch.zeros(2, 3, 8), [5])
    with pytest.raises(ValueError, match="z:"):
        vae.decode(torch.zeros(2, 4, 8), [5, 5])
    with pytest.raises(ValueError, match="preset"):
        V.VAEConfig.preset("huge")


@pytest.mark.parametrize("arch", ["transformer", "conv"])
def test_learns_to_reconstruct_a_few_clips(arch):
    torch.manual_seed(0)
    vae = tiny() if arch == "transformer" else tiny_conv()
    t = torch.linspace(0, 3, 24)
    clips = [torch.sin(t[:, None] + torch.linspace(0, 3, 263) * k) for k in range(4)]
    x, mask = pad_batch(clips)
    opt = torch.optim.Adam(vae.parameters(), lr=3e-3)
    first = float(vae.loss_terms(x, mask)["rec"])
    for _ in range(60):
        terms = vae.loss_terms(x, mask)
        opt.zero_grad()
        terms["loss"].backward()
        opt.step()
    assert float(terms["rec"]) < (0.4 if arch == "transformer" else 0.2) * first and float(terms["kl"]) > 0


def test_packaged_checkpoint_reconstructs_held_out_clips():
    vae = V.load_vae()
    assert vae.config["latent_tokens"] * vae.config["latent_dim"] <= 7 * 256
    paths = load_builtin(progress=False)
    ds = V.ContentClips(paths["content"], "test", normalize=False)
    raws = [ds[i]["features"] for i in range(0, 200, 25)]
    recs = vae.decode_raw(vae.encode_raw(raws), [len(r) for r in raws])
    errs = []
    for r, q in zip(raws, recs):
        p, q = V.decode_positions(r.double().numpy()), V.decode_positions(q)
        errs.append(np.linalg.norm((p - p[:, :1]) - (q - q[:, :1]), axis=-1).mean())
    assert 100 * float(np.mean(errs)) <= 5.0  # root-relative MPJPE, cm (issue 9's bar)
    assert 0.05 < float(vae.latent_scale) < 100  # calibrated after training
    assert course_path("vae").stat().st_size <= 10 * 2 ** 20


def test_conv_vae_tokens_are_local_in_time():
    torch.manual_seed(0)
    vae = tiny_conv().eval()
    # token i sees frames near 4i only: changing the last frames leaves the first tokens alone
    long = torch.randn(60, 263)
    c = long.clone()
    c[-4:] += 1.0
    torch.testing.assert_close(vae.encode(c[None])[:, :2], vae.encode(long[None])[:, :2])
    assert not torch.allclose(vae.encode(c[None])[:, -2:], vae.encode(long[None])[:, -2:])
    with pytest.raises(ValueError, match="latent_tokens"):
        V.VAEConfig(arch="conv", latent_tokens=7, max_len=64)
    with pytest.raises(ValueError, match="arch"):
        V.VAEConfig(arch="rnn")
