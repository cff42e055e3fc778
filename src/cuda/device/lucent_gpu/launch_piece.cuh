// The launch indices one kernel of the megakernel runs (trace.cuh, run_launch): a piece of
// a launch, whole rows of it, counted from 0 by the piece's counter, in 8x4 tiles of launch
// indices when the launch has more than one row.
#pragma once

#include "lucent_gpu/runtime.cuh"

namespace lucent::gpu {

/// The launch indices of one piece of a launch, counted from 0 by the piece's counter.
struct LaunchPiece {
    unsigned long long first, last;  // linear indices [first, last)
    unsigned long long first_row, end_row;
    unsigned tiles_x;
    bool tiled, one_dimension;
    unsigned long long work;  // the counter's end: indices, or 32 a tile when tiled

    __device__ __forceinline__ LaunchPiece(unsigned long long piece_first,
                                           unsigned long long piece_last) {
        const LaunchParams& p = params;
        first = piece_first;
        last = piece_last;
#if LUCENT_GPU_TILES
        // Launches of several rows: a warp takes an 8x4 tile of launch indices, so
        // neighbouring rays, and their secondary rays, run together (less divergence than a
        // row of 32).
        tiled = p.launch_size.y > 1 || p.launch_size.z > 1;
#else
        tiled = false;
#endif
        one_dimension = p.launch_size.y == 1 && p.launch_size.z == 1;
        first_row = piece_first / p.launch_size.x;
        end_row = piece_last / p.launch_size.x;
        tiles_x = (p.launch_size.x + 7) / 8;
        work = tiled ? 32ull * tiles_x * ((end_row - first_row + 3) / 4) : piece_last - piece_first;
    }

    /// The launch index of counter value `i` (< work); false for a tile's place outside the
    /// launch.
    __device__ __forceinline__ bool coordinates(unsigned long long i, unsigned& x, unsigned& y,
                                                unsigned& z) const {
        const LaunchParams& p = params;
        if (tiled) {
            const unsigned long long tile = i / 32;
            const unsigned place = unsigned(i & 31u);
            x = unsigned(tile % tiles_x) * 8 + (place & 7u);
            const unsigned long long row = first_row + (tile / tiles_x) * 4 + (place >> 3);
            if (x >= p.launch_size.x || row >= end_row) return false;
            y = unsigned(row % p.launch_size.y);
            z = unsigned(row / p.launch_size.y);
            return true;
        }
        const unsigned long long index = first + i;
        if (index >= last) return false;
        if (one_dimension) {  // no divisions (two 64-bit ones below)
            x = unsigned(index);
            y = z = 0;
            return true;
        }
        x = unsigned(index % p.launch_size.x);
        const unsigned long long rest = index / p.launch_size.x;
        y = unsigned(rest % p.launch_size.y);
        z = unsigned(rest / p.launch_size.y);
        return true;
    }
};

}  // namespace lucent::gpu
