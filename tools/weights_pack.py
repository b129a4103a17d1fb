#!/usr/bin/python3
"""Packs a PyTorch U-Net checkpoint into osr-vk's packed weights file.

usage: weights_pack.py CHECKPOINT OUT [--fp16] [--golden DIR]

CHECKPOINT is a state_dict (or a dict holding one under "state_dict"/"model", or a pickled
module) of tools/unet.py's UNet, which has the seed's attribute names (encoder0..encoder3,
decoder0..decoder2), for any base width K. Each BatchNorm (eval statistics) becomes the
per-channel scale and shift that the preceding convolution's epilogue applies after its
activation; each stride-1 ConvTranspose2d becomes the equivalent plain convolution (kernel
transposed in/out and flipped). The byte layout is src/nn_kernels/weights_format.h (parsed
here, so the format's constants are written once) and docs/weights_format.md.

The header's `mapping` and `normalization` are those of weights_format.h unless the
checkpoint dict carries its own `mapping` / `normalization` strings (a model trained on other
maps), which are written instead.

With --golden DIR it also writes DIR/input.f32 (N x 7 x 32 x 32 random maps), DIR/output.f32
(this checkpoint's PyTorch fp32 output for them, N x 3 x 32 x 32) and DIR/golden.json.
Errors (unreadable file, missing or extra keys, wrong shapes) are one line on stderr, exit 2.
"""
from __future__ import annotations

import argparse
import datetime
import json
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


def load_state_dict(path: str) -> dict:
    import torch
    try:
        obj = torch.load(path, map_location="cpu")
    except Exception as e:  # torch raises many kinds for a bad file
        raise PackError(f"{path}: cannot read checkpoint ({type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''})")
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


def build_model(path: str, state: dict):
    import unet
    try:
        k = unet.base_width(state)
    except ValueError as e:
        raise PackError(f"{path}: {e}")
    model = unet.UNet(k)
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


def pack(model, k: int, fp16: bool, source: str, fmt: dict, metadata: dict) -> bytes:
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

    for layer in conv_layers(model):
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

    header = {
        "architecture": fmt["kArchitecture"],
        "base_width": k,
        "map_size": fmt["kMapSize"],
        "in_channels": fmt["kInChannels"],
        "out_channels": fmt["kOutChannels"],
        "dtype": "f16" if fp16 else "f32",
        "mapping": metadata.pop("mapping", fmt["kMappingConcentric"]),
        "normalization": metadata.pop("normalization", fmt["kNormalizationLogMean10"]),
        "layers": table,
        "training": metadata,
    }
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


def checkpoint_metadata(path: str) -> dict:
    """Scalar entries of a checkpoint dict (epoch, loss, ...) plus where the file came from."""
    import torch
    meta: dict = {"source": os.path.basename(path),
                  "packed_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    try:
        obj = torch.load(path, map_location="cpu")
    except Exception:
        return meta
    if isinstance(obj, dict):
        for key, value in obj.items():
            if isinstance(value, (int, float, str, bool)):
                meta[key] = value
    return meta


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
        state = load_state_dict(args.checkpoint)
        model, k = build_model(args.checkpoint, state)
        metadata = checkpoint_metadata(args.checkpoint)
        if args.normalization:
            known = (fmt["kNormalizationLogMean10"], fmt["kNormalizationLogMean10Absolute"])
            if args.normalization not in known:
                raise PackError(f"--normalization {args.normalization}: not one of {', '.join(known)}")
            metadata["normalization"] = args.normalization
        blob = pack(model, k, args.fp16, args.checkpoint, fmt, metadata)
        Path(args.out).write_bytes(blob)
        if args.golden:
            write_golden(model, args.golden, args.golden_maps, args.seed, k)
    except PackError as e:
        print(f"weights_pack.py: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"weights_pack.py: {e.filename}: {e.strerror}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
