"""The seed's U-Net (IISPT thesis, Appendix B) as a PyTorch module for any base width K.

This is the single definition the packer (weights_pack.py) and training share. Attribute
names and nn.Sequential indices are the thesis' (encoder0..encoder3, decoder0..decoder2), so a
state_dict saved from the seed's IISPTNet loads into UNet(k=64) as is.
Input N x 7 x 32 x 32 (radiance RGB, normal XYZ, distance), output N x 3 x 32 x 32.
"""
from __future__ import annotations

import torch
from torch import nn

IN_CHANNELS = 7
OUT_CHANNELS = 3
LEAKY_SLOPE = 0.2


def _up() -> nn.Module:
    # nn.Upsample(mode="bilinear") without align_corners means align_corners=False; say so.
    return nn.Upsample(scale_factor=2, mode="bilinear", align_corners=False)


class UNet(nn.Module):
    def __init__(self, k: int = 64) -> None:
        super().__init__()
        self.k = k
        lr = lambda: nn.LeakyReLU(LEAKY_SLOPE)  # noqa: E731
        self.encoder0 = nn.Sequential(
            nn.Conv2d(IN_CHANNELS, k, 3, stride=1, padding=1), lr(),
            nn.Conv2d(k, k, 3, stride=1, padding=1), lr())
        self.encoder1 = nn.Sequential(
            nn.MaxPool2d(2),
            nn.Conv2d(k, 2 * k, 3, stride=1, padding=1), lr(), nn.BatchNorm2d(2 * k),
            nn.Conv2d(2 * k, 2 * k, 3, stride=1, padding=1), lr())
        self.encoder2 = nn.Sequential(
            nn.MaxPool2d(2),
            nn.Conv2d(2 * k, 4 * k, 3, stride=1, padding=1), lr(), nn.BatchNorm2d(4 * k),
            nn.Conv2d(4 * k, 4 * k, 3, stride=1, padding=1), lr())
        self.encoder3 = nn.Sequential(
            nn.MaxPool2d(2),
            nn.Conv2d(4 * k, 8 * k, 3, stride=1, padding=1), lr(), nn.BatchNorm2d(8 * k),
            nn.Conv2d(8 * k, 4 * k, 3, stride=1, padding=1), lr(), _up())
        self.decoder0 = nn.Sequential(
            nn.ConvTranspose2d(8 * k, 4 * k, 3, stride=1, padding=1), lr(), nn.BatchNorm2d(4 * k),
            nn.ConvTranspose2d(4 * k, 2 * k, 3, stride=1, padding=1), lr(), _up())
        self.decoder1 = nn.Sequential(
            nn.ConvTranspose2d(4 * k, 2 * k, 3, stride=1, padding=1), lr(), nn.BatchNorm2d(2 * k),
            nn.ConvTranspose2d(2 * k, k, 3, stride=1, padding=1), lr(), _up())
        self.decoder2 = nn.Sequential(
            nn.ConvTranspose2d(2 * k, k, 3, stride=1, padding=1), lr(),
            nn.ConvTranspose2d(k, k, 3, stride=1, padding=1), lr(),
            nn.Conv2d(k, OUT_CHANNELS, 1, stride=1, padding=0), nn.ReLU())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x0 = self.encoder0(x)
        x1 = self.encoder1(x0)
        x2 = self.encoder2(x1)
        x3 = self.encoder3(x2)
        x4 = self.decoder0(torch.cat((x3, x2), 1))
        x5 = self.decoder1(torch.cat((x4, x1), 1))
        return self.decoder2(torch.cat((x5, x0), 1))


def base_width(state_dict: dict[str, torch.Tensor]) -> int:
    """K of a state_dict of this module (encoder0.0.weight is K x 7 x 3 x 3)."""
    w = state_dict.get("encoder0.0.weight")
    if w is None or w.dim() != 4:
        raise ValueError("missing key encoder0.0.weight (not a U-Net state_dict)")
    return int(w.shape[0])


def randomize(model: UNet, seed: int) -> None:
    """Random weights and BatchNorm statistics (tests, benchmarks), in eval mode."""
    g = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for m in model.modules():
            if isinstance(m, (nn.Conv2d, nn.ConvTranspose2d)):
                fan_in = m.weight.shape[1 if isinstance(m, nn.Conv2d) else 0] * 9
                if m.kernel_size == (1, 1):
                    fan_in //= 9
                bound = (6.0 / fan_in) ** 0.5
                m.weight.copy_((torch.rand(m.weight.shape, generator=g) * 2 - 1) * bound)
                m.bias.copy_((torch.rand(m.bias.shape, generator=g) * 2 - 1) * 0.1)
            elif isinstance(m, nn.BatchNorm2d):
                n = m.num_features
                m.weight.copy_(1 + 0.3 * (torch.rand(n, generator=g) * 2 - 1))
                m.bias.copy_(0.2 * (torch.rand(n, generator=g) * 2 - 1))
                m.running_mean.copy_(0.3 * (torch.rand(n, generator=g) * 2 - 1))
                m.running_var.copy_(0.5 + torch.rand(n, generator=g))
    model.eval()
