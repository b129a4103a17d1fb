#!/usr/bin/python3
"""Property tests (Debian's python3-hypothesis) of what the training tools read from users:
the dataset reader (tools/maps_data.py), the weights packer (tools/weights_pack.py) and
train.py's argument and data checks. Each property holds for every generated input: a file
or value the tools cannot use is refused with their own error (DataError, PackError, argparse's
exit 2), never a traceback, and what they accept comes back as written.

Run by CTest (tools/test_properties); a few seconds, no device. Examples per property are
kept modest (OSR_HYPOTHESIS_EXAMPLES, default 25) so that CI stays fast; a longer search:
OSR_HYPOTHESIS_EXAMPLES=2000 /usr/bin/python3 tests/tools/test_properties.py
"""
import contextlib
import io
import json
import os
import struct
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

import numpy as np

# Hypothesis caches Unicode tables under ./.hypothesis by default: keep the source tree clean.
os.environ.setdefault("HYPOTHESIS_STORAGE_DIRECTORY", str(Path(tempfile.gettempdir()) / "osr_hypothesis"))
from hypothesis import HealthCheck, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import arg_types  # noqa: E402
import maps_data  # noqa: E402
import train  # noqa: E402
import weights_pack  # noqa: E402

EXAMPLES = int(os.environ.get("OSR_HYPOTHESIS_EXAMPLES", "25"))
# No example database: CI machines start clean, and a test must not write into the source tree.
SETTINGS = settings(max_examples=EXAMPLES, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# JSON values as a hand-edited or truncated manifest may hold them, infinities included
# (Python's json reads Infinity and NaN).
json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3),
    max_leaves=12)


def maps(rows: int, channels: int, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(0.0, 2.0, (rows, channels, 32, 32)).astype(np.float32)


def write_dataset(folder: Path, shards: list[tuple[int, int]], rng: np.random.Generator,
                  spp: int = 16) -> list[tuple[np.ndarray, np.ndarray]]:
    """A make_dataset.py folder of shards (seed, rows); returns each shard's (input, target)."""
    arrays, entries = [], []
    for i, (seed, rows) in enumerate(shards):
        d = folder / f"shard{i}"
        d.mkdir(parents=True)
        x, y = maps(rows, 7, rng), maps(rows, 3, rng)
        np.save(d / "input.npy", x)
        np.save(d / "target.npy", y)
        arrays.append((x, y))
        entries.append({"path": d.name, "seed": seed})
    (folder / "dataset.json").write_text(json.dumps({"settings": {"reference_spp": spp}, "shards": entries}))
    return arrays


class DatasetReader(unittest.TestCase):
    """maps_data.Shards and load_array: any folder is read or refused with DataError."""

    @SETTINGS
    @given(manifest=json_values)
    @example(manifest={"settings": {"reference_spp": 1}, "shards": [{"path": "a", "seed": float("inf")}]})
    def test_any_manifest_is_read_or_refused(self, manifest):
        with tempfile.TemporaryDirectory() as tmp:
            Path(tmp, "dataset.json").write_text(json.dumps(manifest))
            try:
                maps_data.Shards([tmp])
            except maps_data.DataError as e:
                self.assertIn(tmp, str(e))

    @SETTINGS
    @given(dtype=st.sampled_from(["<f4", "<f8", "<i4", ">f4", "|u1"]),
           shape=st.lists(st.integers(0, 3), min_size=0, max_size=4).map(tuple),
           tail=st.sampled_from([(7, 32, 32), (7, 32, 31), (3, 32, 32), ()]),
           cut=st.one_of(st.none(), st.integers(0, 400)), npz=st.booleans())
    @example(dtype="<f4", shape=(), tail=(7, 32, 32), cut=None, npz=True)
    @example(dtype="<f4", shape=(), tail=(7, 32, 32), cut=4, npz=True)
    def test_any_array_file_is_read_or_refused(self, dtype, shape, tail, cut, npz):
        """load_array returns the array written when it is float32 [N, 7, 32, 32], refuses
        anything else: other dtypes and shapes, a truncated file, an .npz archive."""
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp, "input.npy")
            a = np.arange(int(np.prod(shape + tail)), dtype=np.float64).reshape(shape + tail).astype(dtype)
            with open(path, "wb") as f:
                if npz:
                    np.savez(f, a)
                else:
                    np.save(f, a)
            if cut is not None:
                path.write_bytes(path.read_bytes()[:cut])
            try:
                got = maps_data.load_array(path, (7, 32, 32))
            except maps_data.DataError as e:
                self.assertIn(str(path), str(e))
                return
            self.assertFalse(npz)
            self.assertEqual(got.dtype, np.float32)
            np.testing.assert_array_equal(got, a)

    @SETTINGS
    @given(rows=st.lists(st.integers(0, 4), min_size=1, max_size=4), picks=st.lists(st.integers(0, 10**6), max_size=12),
           seed=st.integers(0, 2**32 - 1))
    def test_batch_is_the_rows_of_the_shards_in_order(self, rows, picks, seed):
        """Shards.batch(rows) is rows of the shards concatenated in manifest order."""
        with tempfile.TemporaryDirectory() as tmp:
            arrays = write_dataset(Path(tmp), [(i, n) for i, n in enumerate(rows)], np.random.default_rng(seed))
            s = maps_data.Shards([tmp])
            x_all = np.concatenate([x for x, _ in arrays])
            y_all = np.concatenate([y for _, y in arrays])
            self.assertEqual(s.count, len(x_all))
            if s.count == 0:
                return
            idx = np.array([p % s.count for p in picks], dtype=np.int64)
            x, y = s.batch(idx)
            np.testing.assert_array_equal(x, x_all[idx])
            np.testing.assert_array_equal(y, y_all[idx])

    @SETTINGS
    @given(k=st.integers(0, 7), seed=st.integers(0, 2**32 - 1))
    def test_symmetries_are_invertible_and_keep_unit_normals(self, k, seed):
        """Each of the 8 symmetries is a bijection of texels (some power of it is the
        identity) and turns normals into unit normals."""
        rng = np.random.default_rng(seed)
        x = maps(2, 7, rng)
        n = rng.normal(size=(2, 3, 32, 32)).astype(np.float32)
        x[:, 3:6] = n / np.linalg.norm(n, axis=1, keepdims=True)
        y, steps = maps_data.symmetry(x, k, True), 1
        while not np.array_equal(y, x):
            y, steps = maps_data.symmetry(y, k, True), steps + 1
            self.assertLessEqual(steps, 4)
        z = maps_data.symmetry(x, k, True)
        np.testing.assert_allclose(np.linalg.norm(z[:, 3:6], axis=1), 1.0, rtol=1e-5)
        self.assertEqual(sorted(z[:, 0].ravel()), sorted(x[:, 0].ravel()))


class TrainChecks(unittest.TestCase):
    """train.py's argument and data checks."""

    OPTIONS = {"--k": "int", "--steps": "int", "--batch": "int", "--threads": "int", "--seed": "seed",
               "--minutes": "float", "--lr": "float", "--eval-s": "float", "--checkpoint-s": "float"}

    @staticmethod
    def valid(kind: str, text: str) -> bool:
        try:
            v = int(text) if kind in ("int", "seed") else float(text)
        except ValueError:
            return False
        if kind == "seed":
            return 0 <= v < 2**32
        return v >= 1 if kind == "int" else (v > 0 and v != float("inf"))

    @SETTINGS
    @given(option=st.sampled_from(sorted(OPTIONS)),
           text=st.one_of(st.integers(-2**40, 2**40).map(str), st.floats().map(repr),
                          st.text(alphabet="0123456789.-e+infa ", max_size=8)))
    def test_every_number_is_checked_at_parse(self, option, text):
        """A value is accepted exactly when it is in the option's domain; a refused one is
        argparse's exit 2 with a last line naming the option, before any work."""
        argv = ["data", "--val", "val", "--out", "run", f"{option}={text}"]
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err):
                args = train.parse_args(argv)
        except SystemExit as e:
            self.assertEqual(e.code, 2)
            self.assertFalse(self.valid(self.OPTIONS[option], text), f"{option}={text} refused: {err.getvalue()}")
            self.assertIn(option, err.getvalue().strip().splitlines()[-1])
            return
        self.assertTrue(self.valid(self.OPTIONS[option], text), f"{option}={text} accepted")
        self.assertIsNotNone(getattr(args, option[2:].replace("-", "_")))

    @SETTINGS
    @given(train_shards=st.lists(st.tuples(st.integers(0, 5), st.integers(0, 3)), min_size=1, max_size=3),
           val_shards=st.lists(st.tuples(st.integers(0, 5), st.integers(0, 3)), min_size=1, max_size=2),
           poison=st.lists(st.sampled_from([np.nan, np.inf, 0.0, -1.0, 1e-30]), max_size=4),
           seed=st.integers(0, 2**32 - 1))
    def test_data_is_checked_before_training(self, train_shards, val_shards, poison, seed):
        """load_data refuses overlapping scenes and sets without usable maps with DataError;
        what it accepts is finite, and every row is either kept or counted as dropped."""
        rng = np.random.default_rng(seed)
        with tempfile.TemporaryDirectory() as tmp:
            t, v = Path(tmp, "train"), Path(tmp, "val")
            written = write_dataset(t, train_shards, rng) + write_dataset(v, val_shards, rng)
            # Some rows made unusable: non-finite, black, or a one-shot map far darker than its target.
            for i, value in enumerate(poison):
                shard = i % len(train_shards)
                x, _ = written[shard]
                if len(x):
                    x[i % len(x), i % 7] = value
                    np.save(t / f"shard{shard}" / "input.npy", x)
            try:
                tr, va = train.load_data([str(t)], str(v))
            except maps_data.DataError as e:
                overlap = {s for s, _ in train_shards} & {s for s, _ in val_shards}
                self.assertTrue(overlap or "no usable maps" in str(e), str(e))
                return
            self.assertFalse({s for s, _ in train_shards} & {s for s, _ in val_shards})
            self.assertEqual(tr.count + tr.dropped, sum(n for _, n in train_shards))
            self.assertTrue(np.isfinite(tr.x).all() and np.isfinite(tr.t).all())
            self.assertGreater(tr.count, 0)
            self.assertGreater(va.count, 0)

    def test_missing_folder_is_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaisesRegex(maps_data.DataError, "no dataset.json"):
                train.load_data([tmp], tmp)


class WeightsPack(unittest.TestCase):
    """weights_pack.py: what it writes is what weights_format.h specifies, and a file that is
    not a checkpoint is one line and exit 2."""

    FMT = weights_pack.read_format()

    @SETTINGS
    @given(k=st.integers(1, 3), fp16=st.booleans(), image=st.booleans(), seed=st.integers(0, 2**31),
           metadata=st.dictionaries(st.text(min_size=1, max_size=6),
                                    st.one_of(st.integers(-2**40, 2**40), st.text(max_size=6), st.booleans(),
                                              st.floats(allow_nan=False, allow_infinity=False)), max_size=3))
    def test_packed_file_follows_the_format(self, k, fp16, image, seed, metadata):
        import image_unet
        import torch
        import unet
        torch.manual_seed(seed)
        model = (image_unet.ImageUNet(k) if image else unet.UNet(k)).eval()
        data = weights_pack.pack(model, k, fp16, "test", self.FMT, dict(metadata))
        f = self.FMT
        self.assertEqual(data[:8], f["kWeightsMagic"].encode())
        version, crc = struct.unpack_from("<II", data, f["kOffsetVersion"])
        header_bytes, data_offset, data_bytes = struct.unpack_from("<QQQ", data, f["kOffsetHeaderBytes"])
        self.assertEqual(version, f["kWeightsVersion"])
        self.assertEqual(crc, zlib.crc32(data[f["kPrefixBytes"]:]))
        self.assertEqual(data_offset % f["kDataAlignment"], 0)
        self.assertGreaterEqual(data_offset, f["kPrefixBytes"] + header_bytes)
        self.assertEqual(len(data), data_offset + data_bytes)
        header = json.loads(data[f["kPrefixBytes"]:f["kPrefixBytes"] + header_bytes])
        self.assertEqual(header["base_width"], k)
        state = model.state_dict()
        for layer in header["layers"]:
            for name, t in layer["tensors"].items():
                self.assertEqual(t["offset"] % f["kDataAlignment"], 0)
                self.assertLessEqual(t["offset"] + t["bytes"], data_bytes)
                dtype = {"f32": "<f4", "f16": "<f2"}[t["dtype"]]
                values = np.frombuffer(data, dtype, int(np.prod(t["shape"])), data_offset + t["offset"])
                self.assertTrue(np.isfinite(values).all())
                if name == "bias" and layer["name"] + ".bias" in state:
                    np.testing.assert_array_equal(values, state[layer["name"] + ".bias"].numpy())

    @SETTINGS
    @given(content=st.one_of(st.binary(max_size=256), json_values.map(lambda v: json.dumps(v).encode())))
    def test_a_file_that_is_no_checkpoint_is_one_line(self, content):
        with tempfile.TemporaryDirectory() as tmp:
            ckpt, out = Path(tmp, "model.pt"), Path(tmp, "model.osrw")
            ckpt.write_bytes(content)
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                code = weights_pack.main([str(ckpt), str(out)])
            self.assertEqual(code, 2)
            self.assertEqual(len(err.getvalue().strip().splitlines()), 1, err.getvalue())
            self.assertIn(str(ckpt), err.getvalue())
            self.assertFalse(out.exists())

    @SETTINGS
    @given(obj=json_values)
    def test_any_object_is_a_state_dict_or_refused(self, obj):
        try:
            state = weights_pack.load_state_dict("x.pt", obj)
        except weights_pack.PackError as e:
            self.assertTrue(str(e).startswith("x.pt: "))
            return
        self.assertIsInstance(state, dict)

    @SETTINGS
    @given(text=st.text(max_size=12))
    def test_seed_and_counts(self, text):
        """arg_types: seed_int and positive_int accept exactly their domains."""
        for fn, ok in ((arg_types.seed_int, lambda v: 0 <= v < 2**32), (arg_types.positive_int, lambda v: v >= 1)):
            try:
                value = fn(text)
            except Exception as e:
                self.assertEqual(type(e).__name__, "ArgumentTypeError")
                try:
                    self.assertFalse(ok(int(text)))
                except ValueError:
                    pass
                continue
            self.assertTrue(ok(value))


if __name__ == "__main__":
    unittest.main()
