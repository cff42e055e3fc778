#!/usr/bin/env python3
"""Render a sample into a numpy array, as `lucent render` does, and save it.

    render_sample.py [--sample igi] [--scene cornell] [--size 512x512] [--backend auto]
                     [--set vpls=64 ...] [--out image.npy|image.png]

A .png is written 8-bit sRGB through numpy alone (zlib); .npy keeps the linear floats.
"""
import argparse
import struct
import zlib

import numpy as np

import lucent


def write_png(path, rgb):
    """An (H, W, 3) linear RGB image as an 8-bit sRGB PNG."""
    c = np.clip(rgb, 0, 1)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    pixels = np.round(srgb * 255).astype(np.uint8)
    h, w, _ = pixels.shape
    raw = b"".join(b"\0" + pixels[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", default="igi")
    parser.add_argument("--scene", default="cornell")
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--set", action="append", default=["vpls=64"], metavar="NAME=VALUE")
    parser.add_argument("--out", default="image.png")
    args = parser.parse_args()

    options = dict(s.split("=", 1) for s in args.set)
    print(f"{args.sample}: its options are {', '.join(lucent.samples()[args.sample]['options'])}")
    w, h = (int(s) for s in args.size.split("x"))
    image = lucent.render(args.sample, scene=args.scene, size=(w, h), backend=args.backend, **options)
    print(f"rendered {image.shape[1]}x{image.shape[0]}, mean {image[..., :3].mean():.4f}")
    if image[..., :3].max() <= 0:
        raise SystemExit("render_sample.py: the image is black")
    if args.out.endswith(".npy"):
        with open(args.out, "wb") as f:
            np.save(f, image)
    else:
        write_png(args.out, image[..., :3])
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
