#!/usr/bin/env python3
"""Render a sample across the processes of an MPI job, as `mpirun lucent render` does.

    mpirun -np 3 python3 render_across_ranks.py [--sample pathtracer] [--size 160x120]
        [--spp 8] [--backend auto] [--threads 0] [--out image.png|image.npy]

Every rank runs this script (SPMD); lucent.Ranks.world() joins them (MPI is initialised by
Lucent, no mpi4py) and every launch of the render is spread over their devices. Every rank
gets the whole image, the image of one process byte for byte; rank 0 alone prints and
writes it. Without mpirun the group is this process alone. docs/distributed.md, "Python".
"""
import argparse
import sys

import numpy as np

import lucent


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", default="pathtracer")
    parser.add_argument("--size", default="160x120")
    parser.add_argument("--spp", type=int, default=8)
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--threads", type=int, default=0, help="CPU workers of each rank")
    parser.add_argument("--out", default="across-ranks.png")
    args = parser.parse_args()
    w, h = (int(s) for s in args.size.split("x"))

    ranks = lucent.Ranks.world()  # every rank calls it: a collective
    # A rank whose render fails (a scene file missing on one node) fails it on every rank
    # alike: lucent.RankError "rank R: ..." (uncaught, rank 0 prints it and the job ends).
    image, report = lucent.render(args.sample, size=(w, h), backend=args.backend,
                                  threads=args.threads, spp=args.spp, ranks=ranks, report=True)
    black = image[..., :3].max() <= 0

    failure = None
    if ranks.rank == 0:
        print(f"{args.sample}: {w}x{h}, {args.spp} spp across {ranks.size} rank(s), "
              f"mean {image[..., :3].mean():.4f}")
        for r, share in enumerate(report.ranks):  # empty with one rank: launches run whole
            print(f"  rank {r}: {share.indices} pixels of the last launch in {share.pieces} "
                  f"pieces, busy {share.busy_ms:.1f} ms")
        try:
            if black:
                raise RuntimeError("the image is black")
            if args.out.endswith(".npy"):
                with open(args.out, "wb") as f:
                    np.save(f, image)
            else:
                lucent.write_image(args.out, image)
            print(f"wrote {args.out}")
        except (OSError, RuntimeError) as e:  # lucent.Error is a RuntimeError
            failure = e
    # Every rank learns whether rank 0's write failed, and all exit alike.
    try:
        ranks.agree(failure)
    except lucent.RankError as e:
        if ranks.rank == 0:
            print(f"render_across_ranks.py: {e}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
