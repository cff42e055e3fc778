#!/usr/bin/env python3
"""Render a sample into a numpy array, as `lucent render` does, and save it.

    render_sample.py [--sample igi] [--scene cornell] [--size 512x512] [--backend auto]
                     [--set vpls=64 ...] [--out image.png|image.exr|image.pfm|image.npy]

lucent.write_image writes .png (8-bit sRGB), .exr and .pfm (linear floats) as `lucent
render --out` does; .npy keeps the array as numpy saves it.
"""
import argparse

import numpy as np

import lucent


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
        lucent.write_image(args.out, image)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
