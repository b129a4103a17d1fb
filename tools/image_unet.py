"""The image denoisers (architectures "osr_image_kpn_v4" down to "osr_image_kpn_v1", and
"osr_image_unet_v1") as PyTorch modules for any base width K.

The single definition that training (train_denoiser.py), packing (weights_pack.py) and the
golden tests share; the compute-shader twin runs it from packed weights (src/nn_kernels).
In the spirit of OIDN: the noisy colour plus first-hit albedo and normal in, the clean colour
out, with an HDR-aware input transform (docs/weights_format.md, "Image denoiser"):

  input  N x 9 x H x W: log1p(e * colour) (3), albedo (3, the directional albedo, about
         [0, 1]), normal (3, [-1, 1] world);
         e = the image's exposure scale (image_exposure below), H and W multiples of 8
  output, by architecture:
    osr_image_unet_v1  N x 3 x H x W: y, colour = expm1(max(y, 0)) / e (direct prediction)
    osr_image_kpn_v1   N x 100 x H x W: the logits of four 5 x 5 kernels per pixel, applied in
                       turn with taps 1, 2, 4 and 8 pixels apart to the colour demodulated by
                       the albedo, then remodulated (apply_kernels below)
    osr_image_kpn_v2   the same network and output; each tap's predicted weight is multiplied
                       by fixed normal and depth edge-stopping factors (guide_logits below, the
                       a-trous filter's), trained through, so the network learns only what the
                       geometry cannot tell; needs the first hit's depth besides the input
    osr_image_kpn_v3   also the a-trous filter's B3-spline and variance-scaled luminance
                       factors (filter_logits), averaging linear colour; needs the variance
    osr_image_kpn_v4   v3 with the normal factor of a pixel straddling an edge taken on the
                       mean normals (STRADDLE_LENGTH below), as the a-trous filter does

The kernel-predicting variant (Bako et al. 2017's KPCN, with Vogels et al. 2018's dilated
kernels in sequence) is the shipped one: its output is a convex combination of neighbouring
noisy pixels, so it cannot invent a colour or a level, which a direct predictor trained on
the few thousand crops 2 CPU cores afford does (docs/denoise.md).

Layers (3 x 3 convolutions, zero padding, ReLU; 2 x 2 max-pool; bilinear x2 upsample with
align_corners=False; skip connections concatenated as cat(upsampled, skip)):

  enc0  conv 9 -> K, conv K -> K            (= s0, full size)
  enc1  pool, conv K -> 2K                  (= s1, 1/2)
  enc2  pool, conv 2K -> 2K                 (= s2, 1/4)
  mid   pool, conv 2K -> 4K, up             (1/8 -> 1/4)
  dec2  conv (4K + 2K) -> 2K, up            (cat with s2; 1/4 -> 1/2)
  dec1  conv (2K + 2K) -> 2K, up            (cat with s1; 1/2 -> 1)
  dec0  conv (2K + K) -> K, conv K -> K, conv 1x1 K -> 3 or 100 (no activation)
"""
from __future__ import annotations

import math

import torch
from torch import nn

ARCHITECTURE = "osr_image_unet_v1"
KPN_ARCHITECTURE = "osr_image_kpn_v1"
GUIDED_ARCHITECTURE = "osr_image_kpn_v2"
VARIANCE_ARCHITECTURE = "osr_image_kpn_v3"
STRADDLE_ARCHITECTURE = "osr_image_kpn_v4"
VARIANCE_GUIDED = (STRADDLE_ARCHITECTURE, VARIANCE_ARCHITECTURE)  # need the variance
GEOMETRY_GUIDED = (*VARIANCE_GUIDED, GUIDED_ARCHITECTURE)  # need the depth
KERNEL_ARCHITECTURES = (*GEOMETRY_GUIDED, KPN_ARCHITECTURE)
ARCHITECTURES = (*KERNEL_ARCHITECTURES, ARCHITECTURE)
STAGE = "image_denoiser"
IN_CHANNELS = 9
OUT_CHANNELS = 3
KERNEL_SIZE = 5
KERNEL_LEVELS = 4  # taps 1, 2, 4, 8 apart: the kernels reach 2 (1 + 2 + 4 + 8) = 30 pixels
KERNEL_RADIUS = (KERNEL_SIZE // 2) * ((1 << KERNEL_LEVELS) - 1)
KPN_OUT_CHANNELS = KERNEL_LEVELS * KERNEL_SIZE * KERNEL_SIZE
DEMODULATE_MIN = 0.01  # albedo below this (luminance) is not divided out; channels floored at it
INPUTS = ["colour", "albedo", "normal"]
INPUT_TRANSFORM = "exposure_log1p"  # colour only; albedo and normal as they are
MULTIPLE = 8  # H and W must be multiples of this (three 2 x 2 pools)
EXPOSURE_KEY = 0.18  # e maps the image's log-average luminance to this
# osr_image_kpn_v2's fixed edge-stopping factors, the a-trous filter's (docs/denoise.md): the
# cosine between the unit normals to this power, and exp(-|z_p - z_q| / (GUIDE_SIGMA_DEPTH
# |grad z_p| |p - q| + GUIDE_DEPTH_FLOOR z_p)).
GUIDE_SIGMA_NORMAL = 128.0
GUIDE_SIGMA_DEPTH = 1.0
GUIDE_DEPTH_FLOOR = 1e-3
GUIDE_COS_MIN = 1e-30  # log(cos) below this is (almost) -inf: no weight, but a finite gradient
GUIDE_SLOPE_NONE = 1e30  # a one-sided depth difference past the image's edge: never the smaller
# osr_image_kpn_v3 adds the rest of the a-trous filter's weight to each tap: the B3-spline
# kernel's and exp(-|l_p - l_q| / (SIGMA_LUMINANCE sqrt(v_p) + VARIANCE_FLOOR)), l the linear
# luminance of the level's colour (exposed and demodulated), v_p its variance blurred 3 x 3.
B3_SPLINE = (0.0625, 0.25, 0.375, 0.25, 0.0625)
# osr_image_kpn_v4 (and the a-trous filter) compare a pixel that straddles an edge (its mean
# normal shorter than STRADDLE_LENGTH: its samples saw two faces) with its neighbours by their
# mean normals, exp(-STRADDLE_SIGMA |n_p - n_q|^2): pixels along the edge with about the same
# mix of the two faces count, the faces themselves (a different mix) do not. With the unit
# normals' cosine such a pixel agreed with nobody and kept its noise: half of both denoisers'
# error was on these 1-2 % of the pixels (docs/denoise.md, "Pixels on edges").
STRADDLE_LENGTH = 0.9
STRADDLE_SIGMA = 16.0
SIGMA_LUMINANCE = 4.0
VARIANCE_FLOOR = 1e-6


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


def _luminance(c: torch.Tensor) -> torch.Tensor:
    return 0.2126 * c[:, 0:1] + 0.7152 * c[:, 1:2] + 0.0722 * c[:, 2:3]


def demodulator(albedo: torch.Tensor) -> torch.Tensor:
    """What colour is divided by before filtering: the albedo, each channel at least
    DEMODULATE_MIN, or 1 where the albedo's luminance is below it (misses, black surfaces),
    whose light is filtered as it is. As the a-trous filter does (docs/denoise.md)."""
    return torch.where(_luminance(albedo) < DEMODULATE_MIN, torch.ones_like(albedo), albedo.clamp(min=DEMODULATE_MIN))


def depth_gradient(depth: torch.Tensor) -> torch.Tensor:
    """|grad z| per pixel (N x 1 x H x W): across x and across y the smaller of the two
    one-sided differences (only the one inside the image at its edge), the larger of the two
    axes. Unlike the a-trous filter's central difference, which spans a depth step at the
    pixels beside it and so lets them average across it, the smaller side is the surface's own
    slope there."""
    big = GUIDE_SLOPE_NONE
    dx = (depth[..., :, 1:] - depth[..., :, :-1]).abs()
    dy = (depth[..., 1:, :] - depth[..., :-1, :]).abs()
    gx = torch.minimum(nn.functional.pad(dx, (0, 1), value=big), nn.functional.pad(dx, (1, 0), value=big))
    gy = torch.minimum(nn.functional.pad(dy, (0, 0, 0, 1), value=big), nn.functional.pad(dy, (0, 0, 1, 0), value=big))
    return torch.maximum(gx, gy)


def guide_logits(normal: torch.Tensor, depth: torch.Tensor, level: int, straddle: bool = False) -> torch.Tensor:
    """log of osr_image_kpn_v2's fixed factor on each tap (N x 25 x H x W) at this level: the
    normals' cosine^GUIDE_SIGMA_NORMAL times the depth factor (see the constants; |grad z| is
    depth_gradient's); a miss (depth 0) only with misses (factor 1 between two). The centre
    tap's is 0 (factor 1). straddle (osr_image_kpn_v4): where the pixel's mean normal is
    shorter than STRADDLE_LENGTH, the normal factor is exp(-STRADDLE_SIGMA |n_p - n_q|^2) on
    the mean normals instead."""
    n, _, h, w = normal.shape
    step = 1 << level
    pad = (KERNEL_SIZE // 2) * step
    taps = KERNEL_SIZE * KERNEL_SIZE
    unit = normal / normal.norm(dim=1, keepdim=True).clamp(min=1e-12)
    nq = nn.functional.unfold(unit, KERNEL_SIZE, dilation=step, padding=pad).view(n, 3, taps, h, w)
    cos = (unit.unsqueeze(2) * nq).sum(1)
    normal_term = GUIDE_SIGMA_NORMAL * torch.log(cos.clamp(min=GUIDE_COS_MIN))
    if straddle:
        mq = nn.functional.unfold(normal, KERNEL_SIZE, dilation=step, padding=pad).view(n, 3, taps, h, w)
        mixed = -STRADDLE_SIGMA * ((normal.unsqueeze(2) - mq) ** 2).sum(1)
        normal_term = torch.where(normal.norm(dim=1, keepdim=True) < STRADDLE_LENGTH, mixed, normal_term)
    zq = nn.functional.unfold(depth, KERNEL_SIZE, dilation=step, padding=pad).view(n, taps, h, w)
    offsets = torch.arange(taps, dtype=depth.dtype, device=depth.device)
    dist = torch.hypot(offsets % KERNEL_SIZE - KERNEL_SIZE // 2, torch.div(offsets, KERNEL_SIZE,
                       rounding_mode="floor") - KERNEL_SIZE // 2).view(1, taps, 1, 1) * step
    scale = GUIDE_SIGMA_DEPTH * depth_gradient(depth) * dist + GUIDE_DEPTH_FLOOR * depth
    dz = (depth - zq).abs() / scale.clamp(min=1e-30)  # 0 only at a miss, where it is not used
    hit = (depth > 0) & (zq > 0)
    g = torch.where(hit, normal_term - torch.where(hit, dz, 0),
                    torch.where((depth > 0) == (zq > 0), 0.0, GUIDE_SIGMA_NORMAL * math.log(GUIDE_COS_MIN)))
    g[:, taps // 2] = 0
    return g


def _blur3(v: torch.Tensor) -> torch.Tensor:
    """The 3 x 3 Gaussian (1 2 1 / 4 per axis) of N x 1 x H x W, normalized by the weights
    inside the image, as the a-trous filter blurs the variance."""
    k = torch.tensor([0.25, 0.5, 0.25], dtype=v.dtype, device=v.device)
    k2 = (k[:, None] * k[None, :]).view(1, 1, 3, 3)
    ones = torch.ones_like(v[:1])
    return nn.functional.conv2d(v, k2, padding=1) / nn.functional.conv2d(ones, k2, padding=1)


def filter_logits(d: torch.Tensor, v: torch.Tensor, level: int) -> torch.Tensor:
    """osr_image_kpn_v3's fixed a-trous factors on each tap (N x 25 x H x W) at this level, as
    logarithms: the B3-spline weight h_i h_j and the luminance factor
    -|l_p - l_q| / (SIGMA_LUMINANCE sqrt(blur3(v)_p) + VARIANCE_FLOOR) of the level's colour d
    (N x 3 x H x W, linear: v3 averages exposed demodulated colour as the filter does) and
    variance v (N x 1 x H x W)."""
    n, _, h, w = d.shape
    step = 1 << level
    pad = (KERNEL_SIZE // 2) * step
    taps = KERNEL_SIZE * KERNEL_SIZE
    lum = _luminance(d)
    lq = nn.functional.unfold(lum, KERNEL_SIZE, dilation=step, padding=pad).view(n, taps, h, w)
    # (clamped above 0: the square root's gradient at 0 is infinite; 1e-20 moves sigma by 1e-10)
    sigma = SIGMA_LUMINANCE * torch.sqrt(_blur3(v).clamp(min=1e-20)) + VARIANCE_FLOOR
    b = torch.tensor(B3_SPLINE, dtype=d.dtype, device=d.device)
    prior = torch.log(b[:, None] * b[None, :]).reshape(1, taps, 1, 1)
    return prior - (lum - lq).abs() / sigma


def apply_kernels(logits: torch.Tensor, colour: torch.Tensor, albedo: torch.Tensor,
                  e: torch.Tensor, light: torch.Tensor | None = None,
                  guides: tuple[torch.Tensor, torch.Tensor] | None = None,
                  variance: torch.Tensor | None = None, straddle: bool = False) -> torch.Tensor:
    """The kernel-predicting network's colour (N x 3 x H x W) from its logits. Per level, each
    pixel's 25 logits are a softmax over the taps inside the image (taps outside get no weight,
    as the shader's tile edge does), applied to the previous level's colour. The kernels
    average the demodulated colour d, exposed and compressed as t = e d / (1 + lum(e d)): a lamp
    or firefly beside a pixel then adds at most its weight to it, however bright (averaging
    linear colour, a weight of 0.001 on a lamp 1000 times brighter doubles a wall pixel). The
    compression is inverted exactly after the last level (lum(t) < 1 for any average).
    light (N x 1 x H x W, optional): the share of each pixel's camera rays that saw light
    directly; such a pixel keeps its colour and is no other pixel's tap, as in the shader.
    guides (normal N x 3 x H x W, depth N x 1 x H x W; osr_image_kpn_v2): each tap's logit
    gets guide_logits added, i.e. its weight is multiplied by the fixed edge-stopping factors.
    variance (N x 1 x H x W; osr_image_kpn_v3): the variance of each pixel's luminance,
    demodulated and exposed as the colour is; each level's logits get filter_logits added, and
    each level passes on the variance of its average (the sum of squared weights times the
    taps' variances), as the a-trous filter does. straddle (osr_image_kpn_v4): guide_logits
    compares the pixels that straddle an edge by their mean normals."""
    n, _, h, w = colour.shape
    scale = demodulator(albedo)
    x = colour.clamp(min=0) / scale * e.view(-1, 1, 1, 1)
    v = None
    if variance is not None:
        # The filter's factors keep a firefly out of its neighbours' averages (its luminance is
        # far from theirs in units of their noise), so v3 averages linear colour, unbiased,
        # as the filter does; the others average the compressed colour.
        ev = e.view(-1, 1, 1, 1)
        v = variance.clamp(min=0) * ev * ev / _luminance(scale) ** 2
        d = x
    else:
        d = x / (1 + _luminance(x))
    taps = KERNEL_SIZE * KERNEL_SIZE
    ones = torch.ones(1, 1, h, w, dtype=d.dtype, device=d.device)
    for level in range(KERNEL_LEVELS):
        step = 1 << level
        pad = (KERNEL_SIZE // 2) * step
        shifted = nn.functional.unfold(d, KERNEL_SIZE, dilation=step, padding=pad).view(n, 3, taps, h, w)
        inside = nn.functional.unfold(ones, KERNEL_SIZE, dilation=step, padding=pad).view(1, taps, h, w)
        counts = inside
        if light is not None:
            lit = (light > 0).to(d.dtype)
            lit_tap = nn.functional.unfold(lit, KERNEL_SIZE, dilation=step, padding=pad).view(n, taps, h, w)
            counts = inside * (1 - lit_tap) * (1 - lit)
            counts[:, taps // 2] = 1
        lg = logits[:, level * taps:(level + 1) * taps]
        if guides is not None:
            lg = lg + guide_logits(*guides, level, straddle)
        if v is not None:
            lg = lg + filter_logits(d, v, level)
        lg = lg.masked_fill(counts == 0, -torch.inf)
        weights = torch.softmax(lg, 1)
        d = (shifted * weights.unsqueeze(1)).sum(2)
        if v is not None:
            vq = nn.functional.unfold(v, KERNEL_SIZE, dilation=step, padding=pad).view(n, taps, h, w)
            v = (weights * weights * vq).sum(1, keepdim=True)
    x = d if v is not None else d / (1 - _luminance(d)).clamp(min=1e-6)
    return x / e.view(-1, 1, 1, 1) * scale


def denoise(model: "ImageUNet", colour: torch.Tensor, albedo: torch.Tensor, normal: torch.Tensor,
            e: torch.Tensor | None = None, depth: torch.Tensor | None = None,
            variance: torch.Tensor | None = None, light: torch.Tensor | None = None) -> torch.Tensor:
    """The denoised colour (N x 3 x H x W, H and W multiples of 8) by any architecture;
    osr_image_kpn_v2, _v3 and _v4 need the depth (N x 1 x H x W), _v3 and _v4 also the variance of each
    pixel's luminance estimate (N x 1 x H x W, the renderer's `variance` layer). light (N x 1 x H
    x W, optional, the renderer's `light` layer): the kernel variants keep the pixels that saw
    light directly out of their neighbours' averages, as the renderer does."""
    x, e = make_input(colour, albedo, normal, e)
    y = model(x)
    if model.architecture in GEOMETRY_GUIDED:
        if depth is None:
            raise ValueError(f"{model.architecture} needs the depth")
        if model.architecture in VARIANCE_GUIDED:
            if variance is None:
                raise ValueError(f"{model.architecture} needs the variance")
            return apply_kernels(y, colour, albedo, e, light, guides=(normal, depth), variance=variance,
                                 straddle=model.architecture == STRADDLE_ARCHITECTURE)
        return apply_kernels(y, colour, albedo, e, light, guides=(normal, depth))
    if model.architecture == KPN_ARCHITECTURE:
        return apply_kernels(y, colour, albedo, e, light)
    return output_colour(y, e)


def _conv(cin: int, cout: int) -> nn.Conv2d:
    return nn.Conv2d(cin, cout, 3, stride=1, padding=1)


def _up() -> nn.Module:
    return nn.Upsample(scale_factor=2, mode="bilinear", align_corners=False)


class ImageUNet(nn.Module):
    def __init__(self, k: int = 16, architecture: str = KPN_ARCHITECTURE) -> None:
        super().__init__()
        if architecture not in ARCHITECTURES:
            raise ValueError(f"unknown image denoiser architecture '{architecture}'")
        self.k = k
        self.architecture = architecture
        out = KPN_OUT_CHANNELS if architecture in KERNEL_ARCHITECTURES else OUT_CHANNELS
        relu = lambda: nn.ReLU()  # noqa: E731
        self.enc0 = nn.Sequential(_conv(IN_CHANNELS, k), relu(), _conv(k, k), relu())
        self.enc1 = nn.Sequential(nn.MaxPool2d(2), _conv(k, 2 * k), relu())
        self.enc2 = nn.Sequential(nn.MaxPool2d(2), _conv(2 * k, 2 * k), relu())
        self.mid = nn.Sequential(nn.MaxPool2d(2), _conv(2 * k, 4 * k), relu(), _up())
        self.dec2 = nn.Sequential(_conv(4 * k + 2 * k, 2 * k), relu(), _up())
        self.dec1 = nn.Sequential(_conv(2 * k + 2 * k, 2 * k), relu(), _up())
        self.dec0 = nn.Sequential(_conv(2 * k + k, k), relu(), _conv(k, k), relu(),
                                  nn.Conv2d(k, out, 1, stride=1, padding=0))

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


def architecture_of(state_dict: dict[str, torch.Tensor], declared: str | None = None) -> str:
    """Which variant a state_dict is, from its head's output channels; the two kernel variants
    have the same weights, so a kernel head is `declared` when that is one of them (a
    checkpoint's "architecture"), else osr_image_kpn_v1."""
    w = state_dict.get("dec0.4.weight")
    outs = {OUT_CHANNELS: ARCHITECTURE, KPN_OUT_CHANNELS: KPN_ARCHITECTURE}
    if w is None or w.dim() != 4 or int(w.shape[0]) not in outs:
        raise ValueError("no dec0.4.weight with 3 or 100 outputs (not an image U-Net state_dict)")
    found = outs[int(w.shape[0])]
    return declared if found == KPN_ARCHITECTURE and declared in KERNEL_ARCHITECTURES else found


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
