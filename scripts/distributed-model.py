#!/usr/bin/env python3
"""The efficiency model of docs/distributed.md ("Model"), for 1 to 256 nodes.

Each figure it rests on is a measurement of docs/distributed.md: per-frame work on one node,
the bytes a frame's launches gather, the ranks' imbalance, and MPI's latency and
bandwidth (lucent-ranks-bench). Network figures between nodes were not measured (one
machine): NET_* below are the assumed InfiniBand HDR link, and the model is also evaluated
with the shared-memory figures measured between ranks on the device machine.

    python3 scripts/distributed-model.py
"""
import math

# Measured (docs/distributed.md, "Figures"): one-node work per frame, ms.
PT_4K_FRAME_CPU16 = 382.5   # path tracer 3840x2160, 1 spp, 16 CPU threads (device machine)
PT_4K_FRAME_H200 = 9.47     # the same on the H200
PT_FRAMES = 64
PT_IMAGE = 3840 * 2160 * 16  # one float4 image, bytes
IGI_1080_FRAME_H200 = 24.0  # IGI Sponza canonical 1920x1080, 180 VPLs (docs/multi-device.md)
IGI_BYTES_PER_PIXEL = 305   # gathered per frame (bench igi canonical, LUCENT_MULTI_TRACE)
IGI_LAUNCHES = 3            # spread launches per frame (VPL generation runs whole)
# Max/mean of the ranks' busy times per frame, 4 ranks x 4 threads (device), path tracer:
IMBALANCE_TAIL = 1.029      # kept rows re-balanced, and the shared tail (CPU ranks)
IMBALANCE_KEPT = 1.08       # kept rows re-balanced alone (what GPU ranks do; measured on
                            # CPU ranks, whose speeds wander more than a GPU's)
SHARED_TAIL = 1 / 16        # of the rows, all-gathered each frame (accumulation + image)
PIECE_TAIL = 1 / (2 * 16)   # dynamic pieces: half a piece of 16 per rank, on average

# Links: (name, small-message latency in us, all-gather bandwidth per rank in GB/s).
LINKS = [
    ("shared memory, measured (16 ranks)", 2.07, 2.11),
    ("InfiniBand HDR, assumed", 2.0, 20.0),
]


def allgather_ms(bytes_total, n, latency_us, gbps):
    """Ring all-gather: log2(n) latencies plus (n-1)/n of the bytes through each rank."""
    if n == 1:
        return 0.0
    return latency_us * 1e-3 * math.log2(n) + bytes_total * (n - 1) / n / (gbps * 1e6)


def agreement_ms(n, latency_us):
    return 0.0 if n == 1 else latency_us * 1e-3 * math.log2(n)


def path_tracer(n, frame_ms, link, shared_tail):
    """Index-local accumulation: per frame two agreements and the report's all-gather (with
    the shared tail's elements on CPU ranks); once: the gather before the kept rows
    (accumulation + image) and the image's at the end."""
    _, lat, bw = link
    work = PT_FRAMES * frame_ms
    imbalance = IMBALANCE_TAIL if shared_tail else IMBALANCE_KEPT
    per_frame = frame_ms / n * (imbalance if n > 1 else 1) + 3 * agreement_ms(n, lat)
    if shared_tail:
        per_frame += allgather_ms(2 * PT_IMAGE * SHARED_TAIL, n, lat, bw)
    once = 3 * allgather_ms(PT_IMAGE, n, lat, bw)
    return work / (n * (PT_FRAMES * per_frame + once) / 1) if n > 1 else 1.0


def igi(n, link):
    """Every spread launch all-gathers what it wrote (the G-buffer, indirect light, image)."""
    _, lat, bw = link
    frame = IGI_1080_FRAME_H200
    gathered = IGI_BYTES_PER_PIXEL * 1920 * 1080
    t = frame / n * (1 + PIECE_TAIL) + IGI_LAUNCHES * 2 * agreement_ms(n, lat) + \
        allgather_ms(gathered, n, lat, bw)
    return frame / (n * t) if n > 1 else 1.0


if __name__ == "__main__":
    nodes = [1, 2, 4, 16, 64, 256]
    for link in LINKS:
        print(f"== {link[0]}: latency {link[1]} us, all-gather {link[2]} GB/s per rank")
        print("nodes      " + " ".join(f"{n:>7}" for n in nodes))
        print("PT 4K CPU  " + " ".join(f"{path_tracer(n, PT_4K_FRAME_CPU16, link, True):7.3f}" for n in nodes))
        print("PT 4K H200 " + " ".join(f"{path_tracer(n, PT_4K_FRAME_H200, link, False):7.3f}" for n in nodes))
        print("IGI 1080p  " + " ".join(f"{igi(n, link):7.3f}" for n in nodes))
