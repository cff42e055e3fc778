#!/usr/bin/python3
"""Streaks in few-round TEA noise (docs/tea-rounds.md): measurements and figures.

TEA is written again here in numpy, so that constructions Lucent does not use can be
measured beside the ones it does. Each construction is an input block (v0, v1) per pixel
or lattice point, a key, and a way to read a value in [0, 1) from the output block.

    /usr/bin/python3 docs/tea-rounds/measure.py                 # the tables
    /usr/bin/python3 docs/tea-rounds/measure.py --images DIR    # and the PNGs into DIR
    /usr/bin/python3 docs/tea-rounds/measure.py --check build/lucent
        # and check that Lucent's `lucent noise` images equal this script's construction

Needs numpy only (PNG written with zlib, PFM read by hand).
"""
import argparse
import os
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np

U32 = np.uint32
DELTA = 0x9E3779B9
ZAFAR_KEY = (0xA341316C, 0xC8013EA4, 0xAD90777D, 0x7E95761E)  # lucent::zafar_tea_key()
LOW24 = U32(0xFFFFFF)


def tea(v0, v1, rounds, key=ZAFAR_KEY, grow_sum=True):
    """TEA in `rounds` cycles (each updates v0 then v1). grow_sum=False is the seed's Figure
    3 as printed: sum stays 0, so every cycle is the same function."""
    v0 = np.asarray(v0, dtype=U32).copy()
    v1 = np.asarray(v1, dtype=U32).copy()
    k = [U32(w) for w in key]
    s = U32(0)
    with np.errstate(over="ignore"):
        for _ in range(rounds):
            if grow_sum:
                s = U32(s + U32(DELTA))
            v0 += ((v1 << U32(4)) + k[0]) ^ (v1 + s) ^ ((v1 >> U32(5)) + k[1])
            v1 += ((v0 << U32(4)) + k[2]) ^ (v0 + s) ^ ((v0 >> U32(5)) + k[3])
    return v0, v1


# Readings of an output block (v0, v1) as a value in [0, 1).
def top24_v0(v0, v1):  # lucent::tea_unit_float(out.x): Lucent before the fix
    return (v0 >> U32(8)).astype(np.float64) / 2**24


def low24_v1(v0, v1):  # lucent::tea_noise_unit(out): Lucent after the fix
    return (v1 & LOW24).astype(np.float64) / 2**24


def low8_v0(v0, v1):  # v0 mod 256 as an 8-bit grey level
    return (v0 & U32(0xFF)).astype(np.float64) / 256


def top24_v1(v0, v1):
    return (v1 >> U32(8)).astype(np.float64) / 2**24


# name: (how the block is fed, reading, grow_sum, what it is)
CONSTRUCTIONS = {
    "lucent-before": ("index", top24_v0, True,
                      "(i, 0), top 24 bits of v0: Lucent before; OptiX-SDK style (index, frame 0)"),
    "lucent-after": ("index", low24_v1, True, "(i, 0), low 24 bits of v1: Lucent now"),
    "xy-top": ("xy", top24_v0, True, "(x, y), top 24 bits of v0"),
    "counter-in-v1": ("index-v1", top24_v0, True, "(0, i), top 24 bits of v0"),
    "fig3-no-sum": ("index", top24_v0, False, "(i, 0), top 24 bits of v0, sum fixed at 0"),
    "top-v1": ("index", top24_v1, True, "(i, 0), top 24 bits of v1"),
    "low-byte-v0": ("index", low8_v0, True, "(i, 0), v0 mod 256 as a grey level"),
}


def blocks(feed, width, height, x0=0, y0=0):
    y, x = np.mgrid[y0:y0 + height, x0:x0 + width]
    x = x.astype(np.int64) & 0xFFFFFFFF
    y = y.astype(np.int64) & 0xFFFFFFFF
    i = (y * width + x) & 0xFFFFFFFF
    zero = np.zeros_like(i)
    if feed == "index":
        return i, zero
    if feed == "index-v1":
        return zero, i
    if feed == "xy":
        return x, y
    raise ValueError(feed)


def white(name, rounds, size):
    feed, read, grow, _ = CONSTRUCTIONS[name]
    v0, v1 = tea(*blocks(feed, size, size), rounds, grow_sum=grow)
    return read(v0, v1)


def lattice_values(name, rounds, x0, y0, w, h):
    """The value drawn at lattice points (x, y): always fed as (x, y), as noise.h does."""
    _, read, grow, _ = CONSTRUCTIONS[name]
    v0, v1 = tea(*blocks("xy", w, h, x0, y0), rounds, grow_sum=grow)
    return read(v0, v1)


def gradient(name, rounds, size, cell=32):
    """One octave of gradient noise as lucent::tea_gradient_noise, pixel centres, [0, 1]."""
    cells = size // cell + 2
    angle = 2 * np.pi * lattice_values(name, rounds, 0, 0, cells, cells)
    gx, gy = np.cos(angle), np.sin(angle)
    p = (np.arange(size) + 0.5) / cell
    iy, ix = np.meshgrid(np.floor(p).astype(int), np.floor(p).astype(int), indexing="ij")
    ty, tx = np.meshgrid(p - np.floor(p), p - np.floor(p), indexing="ij")

    def corner(dx, dy):
        return gx[iy + dy, ix + dx] * (tx - dx) + gy[iy + dy, ix + dx] * (ty - dy)

    def fade(t):
        return t * t * t * (t * (t * 6 - 15) + 10)

    u, v = fade(tx), fade(ty)
    top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * u
    bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * u
    return np.clip(0.5 + (top + (bottom - top) * v) * 0.70710678, 0, 1)


def correlation(a, b):
    a = a - a.mean()
    b = b - b.mean()
    return float((a * b).mean() / np.sqrt((a * a).mean() * (b * b).mean()))


def row_neighbours(img):
    """Correlation of horizontally neighbouring pixels."""
    return correlation(img[:, :-1], img[:, 1:])


def white_stats(img):
    """Neighbour correlations, row-mean spread (1 for independent uniforms), a chi-square of
    horizontal pixel pairs in 16x16 bins (255 degrees of freedom: 255 +- 23), and the
    spectrum's excess at zero horizontal frequency (tests/tea_noise_test.cpp's measure)."""
    n = img.shape[1]
    horizontal = row_neighbours(img)
    vertical = correlation(img[:-1, :], img[1:, :])
    row_ratio = float(img.mean(axis=1).var() * n * 12)
    bins = 16
    pairs = (np.floor(img[:, :-1] * bins) * bins + np.floor(img[:, 1:] * bins)).astype(int)
    counts = np.bincount(pairs.ravel(), minlength=bins * bins)
    expected = pairs.size / bins**2
    chi = float(((counts - expected) ** 2 / expected).sum())
    power = np.log1p(np.abs(np.fft.fft2(img - 0.5)) ** 2)
    power = np.fft.fftshift(power) / power.max()
    band = np.abs(np.arange(n) - n // 2) <= 2
    excess = float(power[:, band].mean() / power[:, ~band].mean())
    return horizontal, vertical, row_ratio, chi, excess


def gradient_stats(name, rounds):
    """Mean dot product of the unit gradients at horizontally and vertically neighbouring
    lattice points over [-128, 128)^2 (0 +- 0.003 for independent directions)."""
    angle = 2 * np.pi * lattice_values(name, rounds, -128, -128, 256, 256)
    gx, gy = np.cos(angle), np.sin(angle)
    dh = float((gx[:, :-1] * gx[:, 1:] + gy[:, :-1] * gy[:, 1:]).mean())
    dv = float((gx[:-1] * gx[1:] + gy[:-1] * gy[1:]).mean())
    return dh, dv


def write_png(path, img):
    """8-bit grey PNG, row 0 at the top."""
    data = np.clip(np.floor(img * 256), 0, 255).astype(np.uint8)
    h, w = data.shape
    raw = b"".join(b"\0" + data[y].tobytes() for y in range(h))

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    channels = 3 if kind == b"PF" else 1
    return np.flipud(data.reshape(h, w, channels)[:, :, 0])  # PFM rows run bottom to top


def check(lucent):
    """Lucent's `noise` images against lucent-after: white exactly, gradient to float
    rounding."""
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for kind, size, ref, tol in (("white", 64, white, 0.0), ("gradient", 256, gradient, 1e-4)):
            for rounds in (2, 4, 8):
                out = os.path.join(tmp, f"{kind}{rounds}.pfm")
                subprocess.run([lucent, "noise", "--kind", kind, "--rounds", str(rounds),
                                "-o", out], check=True, stdout=subprocess.DEVNULL)
                err = float(np.abs(read_pfm(out) - ref("lucent-after", rounds, size)).max())
                good = err <= tol
                ok &= good
                print(f"check {kind:8s} {rounds} rounds: max |lucent - lucent-after| = "
                      f"{err:.2g} {'ok' if good else 'MISMATCH'}")
    return ok


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--images", help="write the figures' PNGs into this folder")
    parser.add_argument("--check", metavar="LUCENT", help="compare with this lucent binary")
    args = parser.parse_args()

    print("White noise, 256x256 blocks, Zafar et al.'s key; independent uniforms give "
          "corr 0 +- 0.004, rows 1 +- 0.09, pairs chi2 255 +- 23, spectrum 1.00")
    print(f"{'construction':15s} {'rounds':>6s} {'corr x':>7s} {'corr y':>7s} {'rows':>7s} "
          f"{'pairs chi2':>11s} {'spectrum':>8s} {'grad dot x':>10s} {'grad dot y':>10s}")
    for name in CONSTRUCTIONS:
        for rounds in (2, 3, 4, 5, 8):
            h, v, rows, chi, excess = white_stats(white(name, rounds, 256))
            dh, dv = gradient_stats(name, rounds)
            print(f"{name:15s} {rounds:6d} {h:7.3f} {v:7.3f} {rows:7.2f} {chi:11.0f} "
                  f"{excess:8.3f} {dh:10.3f} {dv:10.3f}")
    print()
    print("(i, 0), 4 rounds, byte by byte: correlation of horizontally neighbouring pixels")
    v0, v1 = tea(*blocks("index", 256, 256), 4)
    for word, w in (("v0", v0), ("v1", v1)):
        cells = []
        for b in range(4):
            byte = ((w >> U32(8 * b)) & U32(255)).astype(np.float64)
            cells.append(f"bits {8 * b:2d}-{8 * b + 7:2d} {row_neighbours(byte):6.3f}")
        print(f"  {word}: " + "   ".join(cells))
    rng = np.random.default_rng(1)
    keyed = []
    for _ in range(20):
        key = tuple(int(w) for w in rng.integers(0, 2**32, 4))
        keyed.append(row_neighbours(top24_v0(*tea(*blocks("index", 256, 256), 4, key=key))))
    print(f"  20 random keys, (i, 0), top 24 bits of v0, 4 rounds: correlation "
          f"{min(keyed):.3f} to {max(keyed):.3f}")
    print()
    for name in CONSTRUCTIONS:
        print(f"{name:15s} {CONSTRUCTIONS[name][3]}")

    if args.images:
        os.makedirs(args.images, exist_ok=True)
        for rounds in (2, 4, 8):
            for name in ("lucent-before", "lucent-after", "xy-top", "fig3-no-sum", "low-byte-v0"):
                write_png(os.path.join(args.images, f"white_{name}_{rounds}.png"),
                          white(name, rounds, 64))
            for name in ("lucent-before", "lucent-after"):
                write_png(os.path.join(args.images, f"gradient_{name}_{rounds}.png"),
                          gradient(name, rounds, 256))
        print(f"wrote the PNGs into {args.images}")
    if args.check and not check(args.check):
        sys.exit(1)


if __name__ == "__main__":
    main()
