"""argparse value types shared by the tools/ scripts.

A count or a budget that is zero or negative is argparse's one-line usage error (exit 2) at
once, never a traceback from PyTorch, a run that ignores it (train.py --steps 0 trained for
the default 30 minutes, --minutes -1 never stopped) or one that silently does nothing or
something else (make_interiors.py --cameras -2 made 91 cameras).
"""
from __future__ import annotations

import argparse


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expects an integer, got '{text}'") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expects a number, got '{text}'") from None
    if not value > 0 or value == float("inf"):  # also NaN
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def seed_int(text: str) -> int:
    """A random seed: a whole number 0 to 2^32 - 1 (NumPy refuses negative seeds)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expects an integer, got '{text}'") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be 0 to {2**32 - 1}, got {value}")
    return value


def parse_seeds(texts: list[str]) -> list[int]:
    """Seeds as `--seeds 5`, `--seeds 1-20`, `--seeds 1-10,40` (repeatable) say them, in order.
    Raises ValueError naming the part that is not a seed or a range A-B with A <= B."""
    seeds: list[int] = []
    for t in texts:
        for part in t.split(","):
            a, dash, b = part.partition("-")
            try:
                first, last = int(a), int(b) if dash else int(a)
            except ValueError:
                raise ValueError(f"'{part}' is not a seed or a range A-B") from None
            if last < first:
                raise ValueError(f"'{part}' runs backwards (a range A-B needs A <= B)")
            seeds += range(first, last + 1)
    return seeds
