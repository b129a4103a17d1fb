#!/usr/bin/python3
"""Packs a PyTorch U-Net checkpoint into osr-vk's packed weights file.

usage: weights_pack.py CHECKPOINT OUT [--fp16] [--golden DIR]

CHECKPOINT is a state_dict (or a dict holding one under "state_dict"/"model", or a pickled
module) of one of two architectures, told apart by its keys (and by the checkpoint's
"architecture" entry, which must then agree):
- tools/unet.py's UNet ("osr_unet_v1", stage "map_denoiser"), the seed's attribute names
  (encoder0..encoder3, decoder0..decoder2);
- tools/image_unet.py's ImageUNet (stage "image_denoiser": colour, albedo, normal in with the
  exposure_log1p transform, layers in image_unet.LAYERS order), "osr_image_kpn_v2" or
  "osr_image_kpn_v1" (kernel logits out; the same weights, so a v2 checkpoint says so in its
  "architecture" entry) or "osr_image_unet_v1" (colour out), told apart by its head's output
  channels.
Either for any base width K. For the map U-Net, each BatchNorm (eval statistics) becomes the
per-channel scale and shift that the preceding convolution's epilogue applies after its
activation; each stride-1 ConvTranspose2d becomes the equivalent plain convolution (kernel
transposed in/out and flipped). The byte layout is src/nn_kernels/weights_format.h (parsed
here, so the format's constants are written once) and docs/weights_format.md.

The header's `mapping` and `normalization` are those of weights_format.h unless the
checkpoint dict carries its own `mapping` / `normalization` strings (a model trained on other
maps), which are written instead.

With --golden DIR it also writes DIR/input.f32 (N x 7 x 32 x 32 random maps), DIR/output.f32
(this checkpoint's PyTorch fp32 output for them, N x 3 x 32 x 32) and DIR/golden.json; for an
image denoiser, a random HDR image (colour.f32, albedo.f32, normal.f32, each 3 x H x W with H
and W from --golden-size, any size) and output.f32, the denoised colour as the renderer must
compute it: the image padded to multiples of 8 by repeating its last row and column, exposure,
network, output transform or kernels, cropped back (golden_image_denoise below).
Errors (unreadable file, missing or extra keys, wrong shapes) are one line on stderr, exit 2.
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import re
import struct
import sys
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
FORMAT_HEADER = HERE.parent / "src" / "nn_kernels" / "weights_format.h"
sys.path.insert(0, str(HERE))


class PackError(Exception):
    """A problem with the user's input: printed as one line, exit code 2."""


def read_format(path: Path = FORMAT_HEADER) -> dict[str, int | str]:
    """The `inline constexpr` constants of weights_format.h: {kName: int or str}."""
    pattern = re.compile(r"^\s*inline constexpr \w+ (k\w+)(?:\[\])? = (.+);")
    constants: dict[str, int | str] = {}
    for line in path.read_text().splitlines():
        m = pattern.match(line)
        if m:
            value = m.group(2).strip()
            constants[m.group(1)] = value[1:-1] if value.startswith('"') else int(value, 0)
    return constants


def load_checkpoint(path: str):
    import torch
    try:
        return torch.load(path, map_location="cpu")
    except Exception as e:  # torch raises many kinds for a bad file
        raise PackError(f"{path}: cannot read checkpoint ({type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''})")


def load_state_dict(path: str, obj=None) -> dict:
    import torch
    if obj is None:
        obj = load_checkpoint(path)
    if isinstance(obj, torch.nn.Module):
        obj = obj.state_dict()
    if isinstance(obj, dict):
        for key in ("state_dict", "model", "model_state_dict"):
            if key in obj and isinstance(obj[key], dict):
                obj = obj[key]
                break
    if not isinstance(obj, dict) or not all(isinstance(v, torch.Tensor) for v in obj.values()):
        raise PackError(f"{path}: not a state_dict of tensors")
    return {k[len("module."):] if k.startswith("module.") else k: v for k, v in obj.items()}


def unpack_image_denoiser(path: str) -> dict:
    """A packed image denoiser (.osrw) as a checkpoint dict {"model": state_dict, "architecture",
    "base_width"}, the inverse of pack() for stage image_denoiser (plain convolutions, no
    BatchNorm), so a training can start from a shipped model (train_denoiser.py --init)."""
    import numpy as np
    import torch
    fmt = read_format()
    try:
        blob = Path(path).read_bytes()
    except OSError as e:
        raise PackError(f"{path}: {e.strerror}") from None
    prefix = fmt["kPrefixBytes"]
    if len(blob) < prefix or not blob.startswith(fmt["kWeightsMagic"].encode("ascii")):
        raise PackError(f"{path}: not a packed weights file (no {fmt['kWeightsMagic']} magic)")
    (header_bytes,) = struct.unpack_from("<Q", blob, fmt["kOffsetHeaderBytes"])
    (data_offset,) = struct.unpack_from("<Q", blob, fmt["kOffsetDataOffset"])
    (data_bytes,) = struct.unpack_from("<Q", blob, fmt["kOffsetDataBytes"])
    if len(blob) != data_offset + data_bytes:
        raise PackError(f"{path}: {len(blob)} bytes, the header says {data_offset + data_bytes} (truncated?)")
    (checksum,) = struct.unpack_from("<I", blob, fmt["kOffsetChecksum"])
    if zlib.crc32(blob[prefix:]) & 0xFFFFFFFF != checksum:
        raise PackError(f"{path}: checksum mismatch (corrupted)")
    header = json.loads(blob[prefix:prefix + header_bytes])
    if header.get("stage") != fmt["kStageImageDenoiser"]:
        raise PackError(f"{path}: model of stage '{header.get('stage')}', not an image denoiser")
    state = {}
    for layer in header["layers"]:
        for key in ("weight", "bias"):
            t = layer["tensors"][key]
            dtype = np.dtype("<f2" if t["dtype"] == "f16" else "<f4")
            raw = np.frombuffer(blob, dtype, t["bytes"] // dtype.itemsize, data_offset + t["offset"])
            state[f"{layer['name']}.{key}"] = torch.from_numpy(raw.astype(np.float32).reshape(t["shape"]))
    return {"model": state, "architecture": header["architecture"], "base_width": header["base_width"]}


MAP_ARCHITECTURE = "osr_unet_v1"


def detect_architecture(path: str, state: dict, declared) -> str:
    """The architecture of a state_dict, from its first convolution's key; a checkpoint's own
    "architecture" entry must agree."""
    import image_unet
    known = (MAP_ARCHITECTURE, *image_unet.ARCHITECTURES)
    if declared is not None and declared not in known:
        raise PackError(f"{path}: architecture '{declared}' is not one this packer knows ({', '.join(known)})")
    found = ("image" if "enc0.0.weight" in state
             else MAP_ARCHITECTURE if "encoder0.0.weight" in state else None)
    if found is None:
        raise PackError(f"{path}: neither U-Net (no enc0.0.weight or encoder0.0.weight key)")
    if found == "image":
        try:
            found = image_unet.architecture_of(state, declared)
        except ValueError as e:
            raise PackError(f"{path}: {e}") from None
    if declared is not None and declared != found:
        raise PackError(f"{path}: checkpoint says architecture '{declared}' but its keys are {found}'s")
    return found


def build_model(path: str, state: dict, architecture: str = MAP_ARCHITECTURE):
    import image_unet
    import unet
    module = image_unet if architecture in image_unet.ARCHITECTURES else unet
    try:
        k = module.base_width(state)
    except ValueError as e:
        raise PackError(f"{path}: {e}")
    model = image_unet.ImageUNet(k, architecture) if module is image_unet else unet.UNet(k)
    expected = model.state_dict()
    missing = [n for n in expected if n not in state]
    extra = [n for n in state if n not in expected]
    if missing or extra:
        parts = []
        if missing:
            parts.append("missing keys " + ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
        if extra:
            parts.append("unexpected keys " + ", ".join(extra[:6]) + (" ..." if len(extra) > 6 else ""))
        raise PackError(f"{path}: not a K={k} U-Net state_dict: " + "; ".join(parts))
    for name, t in expected.items():
        if tuple(state[name].shape) != tuple(t.shape):
            raise PackError(f"{path}: {name} has shape {tuple(state[name].shape)}, "
                            f"expected {tuple(t.shape)} for K={k}")
    model.load_state_dict(state, strict=True)
    model.eval()
    return model, k


def conv_layers(model) -> list[dict]:
    """The convolutions in execution order, each with its activation and following BatchNorm."""
    from torch import nn
    layers: list[dict] = []
    for seq_name in ("encoder0", "encoder1", "encoder2", "encoder3", "decoder0", "decoder1", "decoder2"):
        for idx, m in enumerate(getattr(model, seq_name)):
            name = f"{seq_name}.{idx}"
            if isinstance(m, (nn.Conv2d, nn.ConvTranspose2d)):
                w = m.weight.detach().double()
                if isinstance(m, nn.ConvTranspose2d):
                    # Stride 1, padding p: the transposed conv equals a conv with padding
                    # k-1-p (= p for k=3, p=1) and the kernel swapped in/out and flipped.
                    assert m.stride == (1, 1) and m.padding == (1, 1) and m.kernel_size == (3, 3)
                    w = w.transpose(0, 1).flip(2, 3)
                layers.append({"name": name, "kernel": m.kernel_size[0], "cin": w.shape[1],
                               "cout": w.shape[0], "weight": w, "bias": m.bias.detach().double(),
                               "activation": "none", "batchnorm": False})
            elif isinstance(m, nn.LeakyReLU):
                layers[-1]["activation"] = "leaky_relu"
                layers[-1]["slope"] = m.negative_slope
            elif isinstance(m, nn.ReLU):
                layers[-1]["activation"] = "relu"
            elif isinstance(m, nn.BatchNorm2d):
                # Follows an activation in this layout: y = scale * act(conv) + shift (exact).
                scale = m.weight.detach().double() / (m.running_var.double() + m.eps).sqrt()
                layers[-1]["batchnorm"] = True
                layers[-1]["bn_name"] = name
                layers[-1]["bn_scale"] = scale
                layers[-1]["bn_shift"] = m.bias.detach().double() - m.running_mean.double() * scale
    return layers


def image_conv_layers(model) -> list[dict]:
    """The image U-Net's convolutions in image_unet.LAYERS order (no BatchNorm, no transposes)."""
    import image_unet
    modules = dict(model.named_modules())
    layers = []
    for name, activation in image_unet.LAYERS:
        m = modules[name]
        w = m.weight.detach().double()
        layers.append({"name": name, "kernel": m.kernel_size[0], "cin": w.shape[1], "cout": w.shape[0],
                       "weight": w, "bias": m.bias.detach().double(), "activation": activation,
                       "batchnorm": False})
    return layers


def header_fields(model, k: int, fmt: dict, metadata: dict) -> dict:
    """The header keys that say what the file is: stage, architecture, shapes, conventions."""
    import image_unet
    if isinstance(model, image_unet.ImageUNet):
        for key in ("inputs", "input_transform"):
            metadata.pop(key, None)
        kpn = model.architecture in image_unet.KERNEL_ARCHITECTURES
        arch = {image_unet.STRADDLE_ARCHITECTURE: "kImageStraddleKpnArchitecture",
                image_unet.VARIANCE_ARCHITECTURE: "kImageVarianceKpnArchitecture",
                image_unet.GUIDED_ARCHITECTURE: "kImageGuidedKpnArchitecture",
                image_unet.KPN_ARCHITECTURE: "kImageKpnArchitecture"}.get(model.architecture, "kImageArchitecture")
        return {"stage": fmt["kStageImageDenoiser"], "architecture": fmt[arch],
                "base_width": k, "in_channels": fmt["kImageInChannels"],
                "out_channels": fmt["kImageKpnOutChannels" if kpn else "kOutChannels"],
                "multiple": fmt["kImageMultiple"],
                "inputs": list(image_unet.INPUTS), "input_transform": image_unet.INPUT_TRANSFORM}
    return {"stage": fmt["kStageMapDenoiser"], "architecture": fmt["kArchitecture"],
            "base_width": k, "map_size": fmt["kMapSize"], "in_channels": fmt["kInChannels"],
            "out_channels": fmt["kOutChannels"],
            "mapping": metadata.pop("mapping", fmt["kMappingConcentric"]),
            "normalization": metadata.pop("normalization", fmt["kNormalizationLogMean10"])}


def pack(model, k: int, fp16: bool, source: str, fmt: dict, metadata: dict) -> bytes:
    import image_unet
    import torch
    align = fmt["kDataAlignment"]
    data = bytearray()
    table = []

    def add(t: torch.Tensor, half: bool) -> dict:
        nonlocal data
        data += b"\0" * (-len(data) % align)
        arr = t.to(torch.float16 if half else torch.float32).contiguous()
        if half and not torch.isfinite(arr).all():
            raise PackError(f"{source}: a weight does not fit fp16 (|w| > 65504); pack without --fp16")
        raw = arr.numpy().astype("<f2" if half else "<f4").tobytes()
        entry = {"dtype": "f16" if half else "f32", "shape": list(arr.shape), "offset": len(data), "bytes": len(raw)}
        data += raw
        return entry

    layers = image_conv_layers(model) if isinstance(model, image_unet.ImageUNet) else conv_layers(model)
    for layer in layers:
        entry = {k2: layer[k2] for k2 in ("name", "kernel", "cin", "cout", "activation", "batchnorm")}
        if "slope" in layer:
            entry["slope"] = layer["slope"]
        if layer["batchnorm"]:
            entry["batchnorm_name"] = layer["bn_name"]
        tensors = {"weight": add(layer["weight"], fp16), "bias": add(layer["bias"], False)}
        if layer["batchnorm"]:
            tensors["bn_scale"] = add(layer["bn_scale"], False)
            tensors["bn_shift"] = add(layer["bn_shift"], False)
        entry["tensors"] = tensors
        table.append(entry)

    header = header_fields(model, k, fmt, metadata)
    header.update({"dtype": "f16" if fp16 else "f32", "layers": table, "training": metadata})
    header_bytes = json.dumps(header, separators=(",", ":")).encode("utf-8")
    prefix_bytes = fmt["kPrefixBytes"]
    data_offset = prefix_bytes + len(header_bytes)
    data_offset += -data_offset % align
    body = header_bytes + b"\0" * (data_offset - prefix_bytes - len(header_bytes)) + bytes(data)
    prefix = bytearray(prefix_bytes)
    magic = fmt["kWeightsMagic"].encode("ascii")
    prefix[0:len(magic)] = magic
    struct.pack_into("<I", prefix, fmt["kOffsetVersion"], fmt["kWeightsVersion"])
    struct.pack_into("<I", prefix, fmt["kOffsetChecksum"], zlib.crc32(body) & 0xFFFFFFFF)
    struct.pack_into("<Q", prefix, fmt["kOffsetHeaderBytes"], len(header_bytes))
    struct.pack_into("<Q", prefix, fmt["kOffsetDataOffset"], data_offset)
    struct.pack_into("<Q", prefix, fmt["kOffsetDataBytes"], len(data))
    return bytes(prefix) + body


def checkpoint_metadata(path: str, obj) -> dict:
    """Scalar entries of a checkpoint dict (epoch, loss, ...) plus where the file came from;
    not a NaN or infinity, which JSON cannot hold."""
    meta: dict = {"source": os.path.basename(path),
                  "packed_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    if isinstance(obj, dict):
        for key, value in obj.items():
            if isinstance(value, (int, float, str, bool)) and not (isinstance(value, float) and not math.isfinite(value)):
                meta[key] = value
    return meta


def golden_image_denoise(model, colour, albedo, normal, depth=None, variance=None):
    """The renderer's image denoising in PyTorch (1 x 3 x H x W each, depth and variance
    1 x 1 x H x W, any H, W): pad to multiples of 8 by repeating the last row and column,
    exposure over the padded image, the network, the output transform or the predicted
    kernels, crop."""
    import image_unet
    import torch.nn.functional as F
    h, w = colour.shape[2], colour.shape[3]
    m = image_unet.MULTIPLE
    pad = (0, -w % m, 0, -h % m)
    padded = [F.pad(t, pad, mode="replicate") for t in (colour, albedo, normal)]
    z = F.pad(depth, pad, mode="replicate") if depth is not None else None
    v = F.pad(variance, pad, mode="replicate") if variance is not None else None
    return image_unet.denoise(model, *padded, depth=z, variance=v)[:, :, :h, :w]


def write_image_golden(model, directory: str, size: tuple[int, int], seed: int, k: int) -> None:
    import image_unet
    import torch
    os.makedirs(directory, exist_ok=True)
    g = torch.Generator().manual_seed(seed)
    w, h = size
    # HDR colour over four decades with some black pixels, albedo in [0, 1], unit normals.
    colour = torch.exp(torch.randn((1, 3, h, w), generator=g) * 2.0 - 1.0)
    colour = colour * (torch.rand((1, 1, h, w), generator=g) > 0.05)
    albedo = torch.rand((1, 3, h, w), generator=g)
    normal = torch.nn.functional.normalize(torch.randn((1, 3, h, w), generator=g), dim=1)
    layers = [("colour", colour), ("albedo", albedo), ("normal", normal)]
    depth = variance = None
    if model.architecture in image_unet.GEOMETRY_GUIDED:
        # Geometry the edge-stopping factors act on: four tilted planes (slightly noisy normals,
        # a depth ramp with a step at each band's edge) and a few misses (depth 0).
        band = (torch.arange(w) * 4 // w).view(1, 1, 1, w).expand(1, 1, h, w)
        faces = torch.nn.functional.normalize(torch.randn((4, 3), generator=g), dim=1)
        faces[:, 2] = faces[:, 2].abs()  # facing the camera, roughly
        noisy = faces[band[0, 0]].permute(2, 0, 1)[None] + 0.05 * torch.randn((1, 3, h, w), generator=g)
        normal = torch.nn.functional.normalize(noisy, dim=1)
        x = torch.arange(w, dtype=torch.float32).view(1, 1, 1, w)
        y0 = torch.arange(h, dtype=torch.float32).view(1, 1, h, 1)
        depth = 2.0 + band.float() * 0.7 + 0.03 * x + 0.02 * y0 + 0.001 * torch.randn((1, 1, h, w), generator=g)
        depth = depth * (torch.rand((1, 1, h, w), generator=g) > 0.03)
        if model.architecture == image_unet.STRADDLE_ARCHITECTURE:
            # The columns where one band meets the next straddle the edge: their film normal
            # is the mean of the two faces', shorter than 1 (mixed in various shares).
            edge = (band[..., 1:] != band[..., :-1])[0, 0, 0].nonzero().flatten() + 1
            share = torch.rand((1, 1, h, edge.numel()), generator=g)
            normal[..., edge] = share * normal[..., edge - 1] + (1 - share) * normal[..., edge]
        layers = [("colour", colour), ("albedo", albedo), ("normal", normal), ("depth", depth)]
    if model.architecture in image_unet.VARIANCE_GUIDED:
        # A variance of the order of the colour's luminance squared (a few samples' worth),
        # over a range of levels, so that the luminance factors are neither all 1 nor all 0.
        lum = 0.2126 * colour[:, 0:1] + 0.7152 * colour[:, 1:2] + 0.0722 * colour[:, 2:3]
        variance = lum * lum * torch.exp(torch.randn((1, 1, h, w), generator=g) * 1.5 - 1.0)
        layers.append(("variance", variance))
    with torch.no_grad():
        y = golden_image_denoise(model.float(), colour, albedo, normal, depth, variance)
    for name, t in (*layers, ("output", y)):
        Path(directory, name + ".f32").write_bytes(t.numpy().astype("<f4").tobytes())
    Path(directory, "golden.json").write_text(json.dumps(
        {"base_width": k, "width": w, "height": h, "seed": seed, "torch": torch.__version__},
        indent=1) + "\n")


def write_golden(model, directory: str, maps: int, seed: int, k: int) -> None:
    import torch
    os.makedirs(directory, exist_ok=True)
    g = torch.Generator().manual_seed(seed)
    x = torch.rand((maps, 7, 32, 32), generator=g) * 2.0 - 0.5
    with torch.no_grad():
        y = model.float()(x)
    Path(directory, "input.f32").write_bytes(x.numpy().astype("<f4").tobytes())
    Path(directory, "output.f32").write_bytes(y.numpy().astype("<f4").tobytes())
    Path(directory, "golden.json").write_text(json.dumps(
        {"base_width": k, "maps": maps, "seed": seed, "input": "input.f32", "output": "output.f32",
         "torch": torch.__version__}, indent=1) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="weights_pack.py", description=__doc__.split("\n", 2)[2],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("checkpoint", help="PyTorch state_dict or checkpoint (.pt/.pth)")
    parser.add_argument("out", help="packed weights file to write")
    parser.add_argument("--fp16", action="store_true", help="store convolution weights as fp16")
    parser.add_argument("--golden", metavar="DIR", help="also write a random input batch and PyTorch's output for it")
    parser.add_argument("--golden-maps", type=int, default=3, help="maps in the golden batch (default 3)")
    parser.add_argument("--golden-size", default="37x21", help="WxH of an image denoiser's golden image (default 37x21)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the golden input (default 1)")
    parser.add_argument("--normalization", help="the header's normalization, overriding the checkpoint's "
                        "(log1p_mean10_v1: output rescaled to the one-shot means; log1p_mean10_abs_v1: as predicted)")
    args = parser.parse_args(argv)
    try:
        import torch
        torch.set_grad_enabled(False)
        fmt = read_format()
        if not os.path.isfile(args.checkpoint):
            raise PackError(f"{args.checkpoint}: no such file")
        obj = load_checkpoint(args.checkpoint)
        state = load_state_dict(args.checkpoint, obj)
        declared = obj.get("architecture") if isinstance(obj, dict) else None
        architecture = detect_architecture(args.checkpoint, state, declared)
        model, k = build_model(args.checkpoint, state, architecture)
        metadata = checkpoint_metadata(args.checkpoint, obj)
        metadata.pop("architecture", None)
        size = re.fullmatch(r"([1-9][0-9]{0,3})x([1-9][0-9]{0,3})", args.golden_size)
        if not size:
            raise PackError(f"--golden-size {args.golden_size}: not WxH (e.g. 37x21)")
        if args.normalization:
            known = (fmt["kNormalizationLogMean10"], fmt["kNormalizationLogMean10Absolute"])
            if args.normalization not in known:
                raise PackError(f"--normalization {args.normalization}: not one of {', '.join(known)}")
            metadata["normalization"] = args.normalization
        blob = pack(model, k, args.fp16, args.checkpoint, fmt, metadata)
        Path(args.out).write_bytes(blob)
        if args.golden and architecture == MAP_ARCHITECTURE:
            write_golden(model, args.golden, args.golden_maps, args.seed, k)
        elif args.golden:
            write_image_golden(model, args.golden, (int(size[1]), int(size[2])), args.seed, k)
    except PackError as e:
        print(f"weights_pack.py: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"weights_pack.py: {e.filename}: {e.strerror}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
