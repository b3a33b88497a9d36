"""Shared model blocks: AdaIN statistics (A Eq. 2), masks, residual blocks, positions."""
import pytest
import torch

from mslib.models.common.layers import PositionalEncoding, ResBlock1d, adain, channel_stats, sinusoid


def test_adain_output_has_style_statistics():
    torch.manual_seed(0)
    c = torch.randn(3, 40, 8) * 2 + 1
    s = torch.randn(3, 25, 8) * 0.5 - 3
    mu_s, sig_s = channel_stats(s)
    out = adain(c, mu_s, sig_s)
    mu_o, sig_o = channel_stats(out)
    assert torch.allclose(mu_o, mu_s, atol=1e-5) and torch.allclose(sig_o, sig_s, atol=1e-3)


def test_adain_switches_keep_the_other_statistic():
    torch.manual_seed(1)
    c, s = torch.randn(2, 30, 4) * 3 + 2, torch.randn(2, 30, 4) * 0.2 - 1
    mu_c, sig_c = channel_stats(c)
    mu_s, sig_s = channel_stats(s)
    mean_only = adain(c, mu_s, sig_s, use_std=False)
    var_only = adain(c, mu_s, sig_s, use_mean=False)
    m, sg = channel_stats(mean_only)
    assert torch.allclose(m, mu_s, atol=1e-5) and torch.allclose(sg, sig_c, atol=1e-4)
    m, sg = channel_stats(var_only)
    assert torch.allclose(m, mu_c, atol=1e-5) and torch.allclose(sg, sig_s, atol=1e-3)


def test_masked_stats_ignore_padding():
    x = torch.randn(1, 10, 3)
    padded = torch.cat([x, 100 * torch.ones(1, 5, 3)], 1)
    mask = torch.arange(15)[None] < 10
    for a, b in zip(channel_stats(padded, mask), channel_stats(x)):
        assert torch.allclose(a, b, atol=1e-5)


def test_resblock_and_positions_shapes():
    assert ResBlock1d(6)(torch.randn(2, 6, 11)).shape == (2, 6, 11)
    emb = sinusoid(torch.arange(5), 7)
    assert emb.shape == (5, 7) and torch.allclose(emb[0, :3], torch.ones(3))
    pe = PositionalEncoding(8, max_len=16)
    assert pe(torch.zeros(2, 16, 8)).shape == (2, 16, 8)
    try:
        pe(torch.zeros(1, 17, 8))
    except ValueError as e:
        assert "max_len" in str(e)
    else:
        raise AssertionError("expected a ValueError")


def test_normalized_round_trip_and_buffers():
    from mslib.models.common.layers import Normalized
    mean, std = torch.randn(263), torch.rand(263) + 0.5
    m = Normalized(mean.numpy(), std.numpy())
    f = torch.randn(2, 5, 263)
    torch.testing.assert_close(m.denormalize(m.normalize(f)), f)
    torch.testing.assert_close(m.normalize(mean.expand(3, 263)), torch.zeros(3, 263))
    assert set(m.state_dict()) == {"mean", "std"}  # the names every packaged checkpoint stores
    plain = Normalized()
    torch.testing.assert_close(plain.normalize(f), f)


def test_pad_last_and_pad_batch_repeat_the_last_frame():
    from mslib.models.common.layers import pad_batch, pad_last
    x = torch.arange(6.0).reshape(3, 2)  # (T=3, C=2)
    torch.testing.assert_close(pad_last(x, 5), torch.tensor([[0., 1], [2, 3], [4, 5], [4, 5], [4, 5]]))
    assert pad_last(x, 2) is x  # never cuts
    batched = pad_last(x[None].expand(4, -1, -1), 4)
    assert batched.shape == (4, 4, 2) and torch.equal(batched[:, -1], batched[:, -2])
    out, mask = pad_batch([x, x[:1]])
    assert out.shape == (2, 3, 2) and mask.tolist() == [[True] * 3, [True, False, False]]
    assert torch.equal(out[1], x[:1].expand(3, 2))
    with pytest.raises(ValueError, match="clips"):
        pad_batch([])
