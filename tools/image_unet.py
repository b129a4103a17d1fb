"""The image denoiser (architecture "osr_image_unet_v1") as a PyTorch module for any base width K.

The single definition that training (train_denoiser.py), packing (weights_pack.py) and the
golden tests share; the compute-shader twin runs it from packed weights (src/nn_kernels).
In the spirit of OIDN: the noisy colour plus first-hit albedo and normal in, the clean colour
out, with an HDR-aware input transform (docs/weights_format.md, "Image denoiser"):

  input  N x 9 x H x W: log1p(e * colour) (3), albedo (3, [0, 1]), normal (3, [-1, 1] world);
         e = the image's exposure scale (image_exposure below), H and W multiples of 8
  output N x 3 x H x W: y, colour = expm1(max(y, 0)) / e

Layers (3 x 3 convolutions, zero padding, ReLU; 2 x 2 max-pool; bilinear x2 upsample with
align_corners=False; skip connections concatenated as cat(upsampled, skip)):

  enc0  conv 9 -> K, conv K -> K            (= s0, full size)
  enc1  pool, conv K -> 2K                  (= s1, 1/2)
  enc2  pool, conv 2K -> 2K                 (= s2, 1/4)
  mid   pool, conv 2K -> 4K, up             (1/8 -> 1/4)
  dec2  conv (4K + 2K) -> 2K, up            (cat with s2; 1/4 -> 1/2)
  dec1  conv (2K + 2K) -> 2K, up            (cat with s1; 1/2 -> 1)
  dec0  conv (2K + K) -> K, conv K -> K, conv 1x1 K -> 3 (no activation)
"""
from __future__ import annotations

import torch
from torch import nn

ARCHITECTURE = "osr_image_unet_v1"
STAGE = "image_denoiser"
IN_CHANNELS = 9
OUT_CHANNELS = 3
INPUTS = ["colour", "albedo", "normal"]
INPUT_TRANSFORM = "exposure_log1p"  # colour only; albedo and normal as they are
MULTIPLE = 8  # H and W must be multiples of this (three 2 x 2 pools)
EXPOSURE_KEY = 0.18  # e maps the image's log-average luminance to this


def image_exposure(colour: torch.Tensor) -> torch.Tensor:
    """e per image (N x 3 x H x W -> N): 0.18 / exp(mean log(1e-4 + luminance)) over pixels
    with luminance > 0; 1 for an all-black image. The shader twin computes the same sum."""
    lum = 0.2126 * colour[:, 0] + 0.7152 * colour[:, 1] + 0.0722 * colour[:, 2]
    lum = lum.flatten(1)
    lit = lum > 0
    logs = torch.where(lit, torch.log(1e-4 + lum), torch.zeros_like(lum))
    count = lit.sum(1)
    mean = logs.sum(1) / count.clamp(min=1)
    e = EXPOSURE_KEY / torch.exp(mean)
    return torch.where(count > 0, e, torch.ones_like(e))


def make_input(colour: torch.Tensor, albedo: torch.Tensor, normal: torch.Tensor,
               e: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """The network input and the exposure e used (N x 3 x H x W each)."""
    if e is None:
        e = image_exposure(colour)
    x = torch.log1p(e.view(-1, 1, 1, 1) * colour.clamp(min=0))
    return torch.cat((x, albedo, normal), 1), e


def output_colour(y: torch.Tensor, e: torch.Tensor) -> torch.Tensor:
    return torch.expm1(y.clamp(min=0)) / e.view(-1, 1, 1, 1)


def _conv(cin: int, cout: int) -> nn.Conv2d:
    return nn.Conv2d(cin, cout, 3, stride=1, padding=1)


def _up() -> nn.Module:
    return nn.Upsample(scale_factor=2, mode="bilinear", align_corners=False)


class ImageUNet(nn.Module):
    def __init__(self, k: int = 16) -> None:
        super().__init__()
        self.k = k
        relu = lambda: nn.ReLU()  # noqa: E731
        self.enc0 = nn.Sequential(_conv(IN_CHANNELS, k), relu(), _conv(k, k), relu())
        self.enc1 = nn.Sequential(nn.MaxPool2d(2), _conv(k, 2 * k), relu())
        self.enc2 = nn.Sequential(nn.MaxPool2d(2), _conv(2 * k, 2 * k), relu())
        self.mid = nn.Sequential(nn.MaxPool2d(2), _conv(2 * k, 4 * k), relu(), _up())
        self.dec2 = nn.Sequential(_conv(4 * k + 2 * k, 2 * k), relu(), _up())
        self.dec1 = nn.Sequential(_conv(2 * k + 2 * k, 2 * k), relu(), _up())
        self.dec0 = nn.Sequential(_conv(2 * k + k, k), relu(), _conv(k, k), relu(),
                                  nn.Conv2d(k, OUT_CHANNELS, 1, stride=1, padding=0))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        s0 = self.enc0(x)
        s1 = self.enc1(s0)
        s2 = self.enc2(s1)
        m = self.mid(s2)
        d2 = self.dec2(torch.cat((m, s2), 1))
        d1 = self.dec1(torch.cat((d2, s1), 1))
        return self.dec0(torch.cat((d1, s0), 1))


# Execution order of the convolutions: (state_dict prefix, activation). The packer writes the
# layer table in this order and the shader twin runs it in this order.
LAYERS = [
    ("enc0.0", "relu"), ("enc0.2", "relu"),
    ("enc1.1", "relu"),
    ("enc2.1", "relu"),
    ("mid.1", "relu"),
    ("dec2.0", "relu"),
    ("dec1.0", "relu"),
    ("dec0.0", "relu"), ("dec0.2", "relu"), ("dec0.4", "none"),
]


def base_width(state_dict: dict[str, torch.Tensor]) -> int:
    w = state_dict.get("enc0.0.weight")
    if w is None or w.dim() != 4:
        raise ValueError("missing key enc0.0.weight (not an image U-Net state_dict)")
    return int(w.shape[0])


def randomize(model: ImageUNet, seed: int) -> None:
    """Random weights (tests, benchmarks), in eval mode."""
    g = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for m in model.modules():
            if isinstance(m, nn.Conv2d):
                fan_in = m.weight.shape[1] * m.weight.shape[2] * m.weight.shape[3]
                bound = (6.0 / fan_in) ** 0.5
                m.weight.copy_((torch.rand(m.weight.shape, generator=g) * 2 - 1) * bound)
                m.bias.copy_((torch.rand(m.bias.shape, generator=g) * 2 - 1) * 0.1)
    model.eval()
