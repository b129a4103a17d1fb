#!/usr/bin/python3
"""The image denoiser's training side, small: the symmetries move colour, albedo, normal and
target together and leave the (world-space) normals' values alone; a Noise2Noise example's
input and target are spp-weighted means of disjoint renders, of at least --min-spp samples; train_denoiser.py --quick trains,
validates, writes the checkpoint the packer reads and resumes, and --init starts the guided
kernels (osr_image_kpn_v2) from a kpn_v1 run and a run from a packed .osrw, which unpacks to
the weights packed; the guided kernels do not average across a
geometric edge; a view without depth takes its depth.npz, and kpn2 refuses data with neither;
the variance of a mean of renders is their weighted sum, kpn3 refuses data without it, and its
kernels with zero logits smooth noise by the variance they are told;
bad data and options are one line, exit 2; tools/train_default_denoiser.sh --quick renders
real interiors with osr-vk, trains and packs, a second make_denoise_data.py run renders
nothing, and renders from before depth was kept get a depth.npz that matches their depth.

Run by CTest (tools/test_denoiser_training) with OSR_BINARY_DIR naming the build folder.
"""
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
sys.path.insert(0, str(TOOLS))
import train_denoiser as td  # noqa: E402

PY = "/usr/bin/python3"


def run(cmd, expect=0):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=500)
    if r.returncode != expect:
        raise AssertionError(f"{' '.join(map(str, cmd))} exited {r.returncode}, not {expect}:\n{r.stderr[-2000:]}")
    return r


def write_view(folder: Path, name: str, spps, colour_of, albedo, normal, variance_of=None) -> None:
    (folder / name).mkdir(parents=True)
    for i, spp in enumerate(spps):
        extra = {"variance": variance_of(i).astype(np.float32)} if variance_of else {}
        np.savez(folder / name / f"in_{i}_{spp}.npz", spp=np.int32(spp), seed=np.int64(i), seconds=np.float32(0),
                 colour=colour_of(i).astype(np.float32), albedo=albedo.astype(np.float16),
                 normal=normal.astype(np.float16), **extra)


class Examples(unittest.TestCase):
    def test_symmetries_move_everything_together_and_keep_normal_values(self):
        # Colour equals albedo, and a pixel's normal is +X where its albedo is red, +Z where
        # green: after any crop and symmetry the relations must still hold pixel by pixel, and
        # the normals must still be exactly +X or +Z (a turned normal would be another vector).
        size = 32
        albedo = np.zeros((3, size, size), np.float32)
        normal = np.zeros((3, size, size), np.float32)
        yy, xx = np.mgrid[0:size, 0:size]
        red = (xx < 20) & (yy < 12)
        albedo[0][red], normal[0][red] = 0.8, 1.0
        albedo[1][~red], normal[2][~red] = 0.6, 1.0
        with tempfile.TemporaryDirectory() as tmp:
            write_view(Path(tmp), "1_c0", [1, 2, 4], lambda i: albedo, albedo, normal)
            view = td.View(Path(tmp) / "1_c0")
        data = type("D", (), {})()
        data.views, data.keys = {"v": view}, ["v"]
        rng = np.random.default_rng(3)
        moved = 0
        for _ in range(12):
            colour, albedo, normal, depth, _, e, target, _, _ = td.make_batch(data, rng, 2, 24)
            np.testing.assert_array_equal(depth.numpy(), 0.0)  # a view without depth gets zeros
            np.testing.assert_allclose(colour.numpy(), albedo.numpy(), rtol=2e-3, atol=1e-4)
            np.testing.assert_allclose(target.numpy(), albedo.numpy(), rtol=2e-3, atol=1e-4)
            n = normal.numpy()
            is_red = albedo[:, 0].numpy() > 0.5
            np.testing.assert_array_equal(n[:, 0] > 0.999, is_red)
            np.testing.assert_array_equal(n[:, 2] > 0.999, ~is_red)
            np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-3)
            moved += int(not np.array_equal(is_red[0], red[:24, :24]))
        self.assertGreater(moved, 0, "no crop or symmetry ever changed the image")

    def test_noise2noise_input_and_target_are_disjoint_weighted_means(self):
        spps = [1, 2, 4, 8]
        value = [1.0, 10.0, 100.0, 1000.0]  # render i is the constant value[i]
        flat = np.zeros((3, 8, 8), np.float32)
        with tempfile.TemporaryDirectory() as tmp:
            write_view(Path(tmp), "1_c0", spps, lambda i: np.full((3, 8, 8), value[i]), flat, flat)
            view = td.View(Path(tmp) / "1_c0")
        rng = np.random.default_rng(1)
        seen = set()
        for _ in range(200):
            colour, _, _, _, _, target, spp, _ = view.example(rng)
            seen.add(spp)
            # Recover the subset from the level (binary, as the counts are powers of two).
            chosen = [i for i in range(4) if spp >> i & 1]
            rest = [i for i in range(4) if i not in chosen]
            self.assertTrue(rest, "an input used every render: no target left")
            self.assertGreaterEqual(sum(spps[i] for i in rest), 0.25 * spp)
            expect_in = sum(spps[i] * value[i] for i in chosen) / spp
            expect_t = sum(spps[i] * value[i] for i in rest) / sum(spps[i] for i in rest)
            self.assertAlmostEqual(float(colour[0, 0, 0]), expect_in, places=2)
            self.assertAlmostEqual(float(target[0, 0, 0]), expect_t, places=2)
        self.assertIn(1, seen)
        self.assertTrue(any(s >= 8 for s in seen), f"only low counts drawn: {sorted(seen)}")
        # --min-spp: only inputs of at least that many samples, still with a target left; a
        # view that reaches none gives its largest.
        drawn = {view.example(rng, min_spp=5)[6] for _ in range(100)}
        self.assertEqual(min(drawn), 5)
        self.assertEqual(max(drawn), 12)
        self.assertEqual({view.example(rng, min_spp=100)[6] for _ in range(10)}, {12})

    def test_variance_of_a_mean_of_independent_renders(self):
        # The mean of renders of 1 and 3 samples weighs them 1/4 and 3/4: its variance is
        # (1/4)^2 v0 + (3/4)^2 v1. Views without variance give zeros; kpn3 refuses them.
        flat = np.zeros((3, 8, 8), np.float32)
        with tempfile.TemporaryDirectory() as tmp:
            write_view(Path(tmp), "1_c0", [1, 3], lambda i: flat, flat, flat,
                       variance_of=lambda i: np.full((1, 8, 8), [16.0, 4.0][i]))
            write_view(Path(tmp), "2_c0", [1, 3], lambda i: flat, flat, flat)
            np.testing.assert_allclose(td.View(Path(tmp) / "1_c0").mean([0, 1])[4], 16 / 16 + 4 * 9 / 16)
            np.testing.assert_array_equal(td.View(Path(tmp) / "2_c0").mean([0, 1])[4], 0.0)
            (Path(tmp) / "dataset.json").write_text('{"spp_list": [1, 3], "views": {"1_c0": {}, "2_c0": {}}}')
            with self.assertRaisesRegex(td.DataError, "2_c0: no variance"):
                td.Dataset([tmp], need_variance=True)

    def test_reference_noise_from_the_spread_of_its_chunks(self):
        # Two independent reference chunks of n samples of a gamma noise with variance c^2 / n:
        # the mean's variance is c^2 / 2n, and the spread's estimate of what it adds to a
        # relMSE, mean(c^2 / 2n / (c^2 + 0.01)), is right to a few per cent over 3 x 64 x 64.
        with tempfile.TemporaryDirectory() as tmp:
            td.write_synthetic(Path(tmp), 4, 1, 64, [1], 32)
            view = td.View(next(Path(tmp).glob("*_c0")))
            self.assertEqual(view.ref_spp, 64)
            clean = view.ref.astype(np.float64)  # close enough in the denominator
            want = float(np.mean(clean ** 2 / 64 / (clean ** 2 + td.RELMSE_EPSILON)))
            self.assertAlmostEqual(view.ref_noise / want, 1.0, delta=0.08)

    def test_depth_per_render_or_from_the_views_depth_npz(self):
        flat = np.zeros((3, 8, 8), np.float32)
        with tempfile.TemporaryDirectory() as tmp:
            write_view(Path(tmp), "1_c0", [1, 2], lambda i: flat, flat, flat)
            self.assertIsNone(td.View(Path(tmp) / "1_c0").depth)
            with self.assertRaisesRegex(td.DataError, "1_c0: no depth"):
                (Path(tmp) / "dataset.json").write_text('{"spp_list": [1, 2], "views": {"1_c0": {}}}')
                td.Dataset([tmp], need_depth=True)
            np.savez(Path(tmp) / "1_c0" / "depth.npz", depth=np.full((1, 8, 8), 3.0, np.float32))
            view = td.View(Path(tmp) / "1_c0")
            self.assertEqual(view.depth.shape, (2, 1, 8, 8))
            np.testing.assert_array_equal(view.mean([0, 1])[3], 3.0)


    def test_light_share_from_the_renders_or_the_views_light_npz_keeps_lamps_out(self):
        # The share of light seen directly, as the renderer's denoisers use it: a lamp pixel
        # keeps its colour and is no tap of its neighbours'. Without it, a wall pixel beside a
        # lamp 1000 times brighter takes a share of it.
        import torch
        import image_unet
        h = w = 16
        colour = np.full((3, h, w), 0.5, np.float32)
        colour[:, 8, 8] = 500.0
        share = np.zeros((1, h, w), np.float32)
        share[0, 8, 8] = 1.0
        flat = np.zeros((3, h, w), np.float32)
        normal = np.zeros((3, h, w), np.float32)
        normal[2] = 1
        with tempfile.TemporaryDirectory() as tmp:
            write_view(Path(tmp), "1_c0", [1, 3], lambda i: colour, flat + 0.5, normal)
            self.assertIsNone(td.View(Path(tmp) / "1_c0").light)
            np.testing.assert_array_equal(td.View(Path(tmp) / "1_c0").mean([0, 1])[5], 0.0)
            np.savez(Path(tmp) / "1_c0" / "light.npz", light=share.astype(np.float16))
            view = td.View(Path(tmp) / "1_c0")
            self.assertEqual(view.light.shape, (2, 1, h, w))
            c, a, n, _, _, light = view.mean([0, 1])
            np.testing.assert_array_equal(light, share)
        model = image_unet.ImageUNet(4, "osr_image_kpn_v4")
        with torch.no_grad():
            model.dec0[4].weight.zero_()
            model.dec0[4].bias.zero_()
        depth = np.full((1, h, w), 2.0, np.float32)
        variance = np.full((1, h, w), 1e6, np.float32)  # so noisy that the luminance factor lets the lamp in
        kept = td.denoise(model, c, a, n, depth, variance, light)
        spread = td.denoise(model, c, a, n, depth, variance)
        self.assertAlmostEqual(float(kept[1, 8, 8]), 500.0, places=2)
        self.assertAlmostEqual(float(kept[1, 8, 9]), 0.5, places=4)
        self.assertGreater(float(spread[1, 8, 9]), 0.6)

class GuidedKernels(unittest.TestCase):
    def test_no_average_across_a_geometric_edge(self):
        # Two halves of one albedo facing different ways (then: at different depths, facing the
        # same way), lit 1 and 0.1, with noise, through uniform kernels: without the guides the
        # edge smears; with them each half keeps its level up to the edge.
        import torch
        import image_unet
        rng = np.random.default_rng(5)
        h, w = 16, 32
        left = np.zeros((1, 1, h, w), bool)
        left[..., : w // 2] = True
        colour = np.where(left, 1.0, 0.1) * rng.uniform(0.5, 1.5, (1, 3, h, w))
        albedo = np.full((1, 3, h, w), 0.5)
        turned = np.where(left, np.array([0, 0, 1.0]).reshape(1, 3, 1, 1), np.array([1.0, 0, 0]).reshape(1, 3, 1, 1))
        facing = np.broadcast_to(np.array([0, 0, 1.0]).reshape(1, 3, 1, 1), (1, 3, h, w))
        plane = 2.0 + 0.01 * np.arange(w).reshape(1, 1, 1, w) * np.ones((1, 1, h, 1))
        stepped = plane + np.where(left, 0.0, 1.0)
        t = lambda a: torch.from_numpy(np.ascontiguousarray(a, np.float32))  # noqa: E731
        c, a = t(colour), t(albedo)
        e = image_unet.image_exposure(c)
        logits = torch.zeros(1, image_unet.KPN_OUT_CHANNELS, h, w)
        edge = slice(w // 2 - 3, w // 2 + 3)
        truth = np.where(left, 1.0, 0.1)[0, 0, :, edge]
        plain = image_unet.apply_kernels(logits, c, a, e)[0, 1, :, edge].numpy()
        self.assertGreater(np.abs(plain / truth - 1).max(), 1.0)  # the dark side gets the bright one's light
        for normal, depth in ((turned, plane), (facing, stepped)):
            out = image_unet.apply_kernels(logits, c, a, e, guides=(t(normal), t(depth)))[0, 1, :, edge].numpy()
            self.assertLess(np.abs(out / truth - 1).max(), 0.15)

    def test_straddling_pixels_compare_mean_normals(self):
        # osr_image_kpn_v4's normal factor: for a pixel whose mean normal is shorter than
        # STRADDLE_LENGTH, -STRADDLE_SIGMA |n_p - n_q|^2 on the mean normals; for any other, the
        # unit normals' cosine^GUIDE_SIGMA_NORMAL as v2's and v3's.
        import torch
        import image_unet
        h, w = 8, 8
        normal = torch.zeros(1, 3, h, w)
        normal[:, 2] = 1.0
        normal[:, :, :, 4] = torch.tensor([0.5, 0.0, 0.5]).view(1, 3, 1)  # a column on the edge
        normal[:, :, :, 5:] = torch.tensor([1.0, 0.0, 0.0]).view(1, 3, 1, 1)
        depth = torch.full((1, 1, h, w), 2.0)
        plain = image_unet.guide_logits(normal, depth, 0)
        mixed = image_unet.guide_logits(normal, depth, 0, straddle=True)
        taps = image_unet.KERNEL_SIZE ** 2
        right, below = taps // 2 + 1, taps // 2 + image_unet.KERNEL_SIZE
        # On the edge column: the face to the right differs by (0.5, 0, -0.5), the column
        # below not at all.
        self.assertAlmostEqual(float(mixed[0, right, 3, 4]), -image_unet.STRADDLE_SIGMA * 0.5, places=4)
        self.assertAlmostEqual(float(mixed[0, below, 3, 4]), 0.0, places=4)
        self.assertLess(float(plain[0, right, 3, 4]), -40.0)  # cos 45 degrees to the 128th
        # Off the edge both are the unit normals' factor.
        torch.testing.assert_close(mixed[..., :4], plain[..., :4])
        torch.testing.assert_close(mixed[..., 5:], plain[..., 5:])


def flat_wall(rng, size: int = 16):
    """Colour (noisy, gamma-distributed), albedo, normal, depth and variance of a flat wall
    facing the camera, 1 x C x size x size tensors."""
    import torch
    colour = torch.from_numpy(rng.gamma(2.0, 0.3, (1, 3, size, size)).astype(np.float32))
    normal = torch.zeros(1, 3, size, size)
    normal[:, 2] = 1
    return (colour, torch.full((1, 3, size, size), 0.6), normal, torch.full((1, 1, size, size), 3.0),
            torch.full((1, 1, size, size), 0.02))


class FilterGuidedKernels(unittest.TestCase):
    def test_zero_logits_filter_noise_by_its_variance(self):
        # osr_image_kpn_v3 with zero logits is the a-trous filter: a flat grey wall with noise
        # of a known variance comes out closer to its level the larger the variance it is told
        # (the luminance factors let more of the noise through when the variance is small), and
        # a variance of 0 keeps the pixels nearly as they are.
        import torch
        import image_unet
        rng = np.random.default_rng(2)
        h, w = 32, 32
        sd = 0.3
        colour = torch.from_numpy((0.5 + sd * rng.standard_normal((1, 1, h, w))).clip(0.01).repeat(3, 1)
                                  .astype(np.float32))
        albedo = torch.full((1, 3, h, w), 0.5)
        normal = torch.zeros(1, 3, h, w)
        normal[:, 2] = 1
        depth = torch.full((1, 1, h, w), 2.0)
        e = image_unet.image_exposure(colour)
        logits = torch.zeros(1, image_unet.KPN_OUT_CHANNELS, h, w)
        errors = []
        for var in (0.0, sd * sd / 16, sd * sd):
            v = torch.full((1, 1, h, w), var)
            out = image_unet.apply_kernels(logits, colour, albedo, e, guides=(normal, depth), variance=v)
            errors.append(float(((out[0, 1] - 0.5) ** 2).mean()))
        noisy = float(((colour[0, 1] - 0.5) ** 2).mean())
        self.assertGreater(errors[0], 0.5 * noisy)
        self.assertLess(errors[2], errors[1])
        self.assertLess(errors[2], 0.05 * noisy)

    def test_loss_relative_to_the_filter_image(self):
        # --loss-scale filter divides each pixel's squared error by the filter's image of the
        # input (the kernels at zero logits), which does not move with the weights: with a zero
        # head the output is that image and both scales give one loss; with another head the
        # divisor is still the filter's.
        import torch
        import image_unet
        rng = np.random.default_rng(4)
        colour, albedo, normal, depth, variance = flat_wall(rng)
        target = torch.from_numpy(rng.gamma(2.0, 0.3, (1, 3, 16, 16)).astype(np.float32))
        e = image_unet.image_exposure(colour)
        model = image_unet.ImageUNet(4, "osr_image_kpn_v4")
        head = model.dec0[4]
        with torch.no_grad():
            head.weight.zero_()
            head.bias.zero_()
        args = (model, colour, albedo, normal, depth, variance, e, target)
        torch.testing.assert_close(td.loss_fn(*args, "filter"), td.loss_fn(*args, "output"))
        image_unet.randomize(model, 3)
        with torch.no_grad():
            f = td.filter_image(model, colour, albedo, normal, depth, variance, e) * e
            y = image_unet.denoise(model, colour, albedo, normal, e, depth, variance) * e
            t = target * e
            expected = ((y - t) ** 2 / (f ** 2 + td.RELMSE_EPSILON)).mean()
        self.assertGreater(float((y - f).abs().max()), 1e-3)
        torch.testing.assert_close(td.loss_fn(*args, "filter"), expected)

    def test_loss_cap_counts_large_relative_errors_linearly(self):
        import torch
        import image_unet
        colour, albedo, normal, depth, variance = flat_wall(np.random.default_rng(6))
        target = colour.clone()
        target[0, :, 3, 5] = 50.0  # a target firefly: relative error far beyond the cap
        target[0, :, 9, 9] = 0.0  # and a pixel the target misses, within 1 of the output
        e = image_unet.image_exposure(colour)
        model = image_unet.ImageUNet(4, "osr_image_kpn_v4")
        image_unet.randomize(model, 5)
        args = (model, colour, albedo, normal, depth, variance, e, target, "output", None)
        with torch.no_grad():
            y = image_unet.denoise(model, colour, albedo, normal, e, depth, variance) * e
            r2 = (y - target * e) ** 2 / (y ** 2 + td.RELMSE_EPSILON)
        self.assertGreater(float(r2.max()), 100.0)
        huber = torch.where(r2 < 4.0, r2, 4.0 * r2.sqrt() - 4.0).mean()
        torch.testing.assert_close(td.loss_fn(*args, cap=2.0), huber)
        torch.testing.assert_close(td.loss_fn(*args, cap=1e6), td.loss_fn(*args))
        # A pixel whose error is 0 (r^2 = 0) gets a finite gradient, and one past the cap a pull
        # of 2 cap r where the plain loss pulls with r^2 (d/dr^2: cap / r instead of 1).
        r2 = torch.tensor([0.0, 1.0, 16.0], requires_grad=True)
        td.huber(r2, 2.0).sum().backward()
        torch.testing.assert_close(r2.grad, torch.tensor([1.0, 1.0, 0.5]))

    def test_quick_run_and_pack(self):
        import torch
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "run"
            r = run([PY, TOOLS / "train_denoiser.py", "--out", out, "--quick", "--arch", "kpn3"])
            self.assertIn("1 spp: relMSE", r.stderr)
            best = torch.load(out / "best.pt", map_location="cpu")
            self.assertEqual(best["architecture"], "osr_image_kpn_v3")
            run([PY, TOOLS / "weights_pack.py", out / "best.pt", out / "model.osrw"])
            header = (out / "model.osrw").read_bytes()[:4096]
            self.assertIn(b"osr_image_kpn_v3", header)


class QuickTraining(unittest.TestCase):
    def test_quick_run_checkpoint_resume(self):
        import torch
        from image_unet import GUIDED_ARCHITECTURE, ImageUNet
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "run"
            r = run([PY, TOOLS / "train_denoiser.py", "--out", out, "--quick"])
            self.assertIn("1 spp: relMSE", r.stderr)
            best = torch.load(out / "best.pt", map_location="cpu")
            self.assertEqual(best["architecture"], GUIDED_ARCHITECTURE)
            for key in ("epoch", "step", "loss", "val_relmse", "val_relmse_1spp", "val_noisy_relmse_1spp",
                        "val_select", "val_less_ref_relmse_1spp"):
                self.assertIn(key, best)
            model = ImageUNet(best["base_width"], best["architecture"])
            model.load_state_dict(best["model"])
            self.assertTrue(all(np.isfinite(v.numpy()).all() for v in best["model"].values()))
            self.assertEqual(len((out / "train.log").read_text().splitlines()), 1)
            # Without --resume an existing run is refused; with it, it continues.
            r = run([PY, TOOLS / "train_denoiser.py", "--out", out, "--quick"], expect=2)
            self.assertIn("--resume", r.stderr.strip().splitlines()[-1])
            r = run([PY, TOOLS / "train_denoiser.py", "--out", out, "--quick", "--resume", "--steps", "8"])
            self.assertIn("resuming", r.stderr)
            self.assertEqual(torch.load(out / "checkpoint.pt", map_location="cpu")["state"]["step"], 8)
            # final.pt is the moving average at the run's end, whichever validation was best.
            final = torch.load(out / "final.pt", map_location="cpu")
            ema = torch.load(out / "checkpoint.pt", map_location="cpu")["ema"]
            self.assertEqual(final["step"], 8)
            self.assertTrue(all(torch.equal(final["model"][k], v) for k, v in ema.items()))

    def test_init_from_a_kpn_v1_run(self):
        import torch
        from image_unet import GUIDED_ARCHITECTURE
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            run([PY, TOOLS / "train_denoiser.py", "--out", t / "v1", "--quick", "--arch", "kpn"])
            v1 = torch.load(t / "v1" / "best.pt", map_location="cpu")
            self.assertEqual(v1["architecture"], "osr_image_kpn_v1")
            r = run([PY, TOOLS / "train_denoiser.py", "--out", t / "v2", "--quick", "--init", t / "v1" / "best.pt",
                     "--steps", "1"])
            self.assertIn("1 spp: relMSE", r.stderr)
            log = (t / "v2" / "train.log").read_text().splitlines()
            self.assertEqual(len(log), 2)  # the starting weights are validated too
            self.assertEqual(torch.load(t / "v2" / "best.pt", map_location="cpu")["architecture"], GUIDED_ARCHITECTURE)
            r = run([PY, TOOLS / "train_denoiser.py", "--out", t / "u", "--quick", "--arch", "unet", "--init",
                     t / "v1" / "best.pt"], expect=2)
            self.assertIn("cannot start a osr_image_unet_v1 run", r.stderr.strip().splitlines()[-1])

    def test_init_from_a_packed_model(self):
        import torch
        from weights_pack import PackError, unpack_image_denoiser
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            run([PY, TOOLS / "train_denoiser.py", "--out", t / "a", "--quick", "--arch", "kpn3"])
            run([PY, TOOLS / "weights_pack.py", t / "a" / "best.pt", t / "a.osrw"])
            best = torch.load(t / "a" / "best.pt", map_location="cpu")
            back = unpack_image_denoiser(str(t / "a.osrw"))
            self.assertEqual(back["architecture"], "osr_image_kpn_v3")
            self.assertEqual(set(back["model"]), set(best["model"]))
            for name, w in best["model"].items():
                self.assertTrue(torch.equal(back["model"][name], w.float()), name)
            r = run([PY, TOOLS / "train_denoiser.py", "--out", t / "b", "--quick", "--arch", "kpn3", "--init",
                     t / "a.osrw", "--steps", "1"])
            self.assertIn("1 spp: relMSE", r.stderr)
            # It started from those weights: its step-0 validation is theirs.
            import json
            start = json.loads((t / "b" / "train.log").read_text().splitlines()[0])
            self.assertEqual(start["step"], 0)
            self.assertAlmostEqual(start["val_relmse"], best["val_relmse"], places=5)
            # A packed file cut short is one line, exit 2.
            (t / "cut.osrw").write_bytes((t / "a.osrw").read_bytes()[:-10])
            with self.assertRaises(PackError):
                unpack_image_denoiser(str(t / "cut.osrw"))
            r = run([PY, TOOLS / "train_denoiser.py", "--out", t / "c", "--quick", "--arch", "kpn3", "--init",
                     t / "cut.osrw"], expect=2)
            self.assertIn("truncated", r.stderr.strip().splitlines()[-1])
            self.assertNotIn("Traceback", r.stderr)

    def test_bad_input_is_one_line(self):
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            td.write_synthetic(t / "a", 1, 2, 16, [1, 2], 0)
            td.write_synthetic(t / "v", 1, 1, 16, [1], 8)  # the same interiors as a
            td.write_synthetic(t / "noref", 2, 1, 16, [1], 0)
            cases = [
                ([t / "nothing", "--val", t / "v"], "no dataset.json"),
                ([t / "a", "--val", t / "v"], "also in the training data"),
                ([t / "a", "--val", t / "noref"], "no view with a reference"),
                ([t / "a", "--val", t / "v", "--crop", "12"], "--crop"),
                ([t / "a", "--val", t / "v", "--k", "0"], "--k"),
                ([t / "a", "--val", t / "v", "--arch", "kpn", "--loss-scale", "filter"], "--loss-scale"),
            ]
            for args, mention in cases:
                with self.subTest(mention=mention):
                    r = run([PY, TOOLS / "train_denoiser.py", *args, "--out", t / "run", "--steps", "1"], expect=2)
                    self.assertIn(mention, r.stderr.strip().splitlines()[-1])
                    self.assertNotIn("Traceback", r.stderr)
            (t / "a" / "100_c0" / "in_0_1.npz").write_bytes(b"not a zip")
            r = run([PY, TOOLS / "train_denoiser.py", t / "a", "--val", t / "noref", "--out", t / "run2"], expect=2)
            self.assertIn("in_0_1.npz", r.stderr.strip().splitlines()[-1])


class RealRenders(unittest.TestCase):
    def test_default_pipeline_quick(self):
        # tools/train_default_denoiser.sh --quick: real renders of generated interiors (training
        # and validation with a reference), a quick training and the packed weights.
        osr_vk = Path(os.environ.get("OSR_BINARY_DIR", ROOT / "build")) / "osr-vk"
        if not osr_vk.is_file():
            self.skipTest(f"{osr_vk} not built")
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp) / "work"
            r = run(["bash", TOOLS / "train_default_denoiser.sh", "--quick", "--work", work, "--osr-vk", osr_vk])
            self.assertNotIn("osr-vk: validation", r.stderr)  # CTest sets OSR_VALIDATION=1
            blob = (work / "run_high" / "model.osrw").read_bytes()
            self.assertIn(b'"stage":"image_denoiser"', blob)
            self.assertIn(b'"architecture":"osr_image_kpn_v4"', blob)
            self.assertTrue((work / "run" / "best.pt").is_file())  # the v4 run that started run_high
            self.assertTrue((work / "run1" / "best.pt").is_file())  # the kpn_v1 run that started run2
            self.assertTrue((work / "run2" / "best.pt").is_file())  # the kpn_v2 run that started run3
            self.assertTrue((work / "run3" / "best.pt").is_file())  # the kpn_v3 run that started it
            files = sorted(work.glob("data/*/in_*.npz"))
            self.assertEqual(len(files), 6)  # 2 views x spp 1, 2, 4
            self.assertTrue(list(work.glob("val/9001_c0/ref_*.npz")))
            data = td.Dataset([str(work / "data")])
            self.assertEqual(len(data.keys), 2)
            for view in data.views.values():
                self.assertEqual(view.colour.shape, (3, 3, 32, 32))
                self.assertGreater(float(view.colour.mean()), 0)
                self.assertGreater(float(view.albedo.max()), 0)
                lengths = np.linalg.norm(view.normal[0], axis=0)
                self.assertGreater(float(np.mean(np.abs(lengths - 1) < 0.05)), 0.5)
                self.assertEqual(view.depth.shape, (3, 1, 32, 32))
                self.assertGreater(float(np.mean(view.depth > 0)), 0.5)  # an interior: most pixels hit
            # Resumable: a second run renders nothing that is already there.
            stamps = [f.stat().st_mtime_ns for f in files]
            r = run([PY, TOOLS / "make_denoise_data.py", work / "data", "--quick", "--osr-vk", osr_vk])
            self.assertEqual([f.stat().st_mtime_ns for f in files], stamps, "a finished render was redone")
            self.assertIn("0 spp rendered", r.stderr)
            # Renders from before depth was kept: one preview render per view gives their depth.
            for f in files:
                old = work / "old" / f.parent.name / f.name
                old.parent.mkdir(parents=True, exist_ok=True)
                with np.load(f) as z:
                    np.savez(old, **{k: z[k] for k in z.files if k not in ("depth", "light")})
            (work / "old" / "dataset.json").write_text((work / "data" / "dataset.json").read_text())
            r = run([PY, TOOLS / "make_denoise_data.py", work / "old", "--quick", "--scenes", work / "data" / "scenes",
                     "--osr-vk", osr_vk])
            self.assertIn("0 spp rendered", r.stderr)
            for name, view in data.views.items():
                guide = np.load(work / "old" / Path(name).name / "depth.npz")["depth"]
                self.assertEqual(guide.shape, (1, 32, 32))
                depth = view.depth[-1]
                hit = depth > 0
                self.assertLess(float(np.median(np.abs(guide[hit] - depth[hit]) / depth[hit])), 0.01)
                # ... and one path render their share of light seen directly (the renders have it).
                share = np.load(work / "old" / Path(name).name / "light.npz")["light"]
                self.assertEqual(share.shape, (1, 32, 32))
                self.assertEqual(view.light.shape, (3, 1, 32, 32))
                self.assertTrue(np.all((share >= 0) & (share <= 1)))
            r = run([PY, TOOLS / "make_denoise_data.py", work / "x", "--size", "30", "--seeds", "1",
                     "--osr-vk", osr_vk], expect=2)
            self.assertIn("--size", r.stderr.strip().splitlines()[-1])


if __name__ == "__main__":
    unittest.main()
