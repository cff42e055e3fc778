// After a launch that GPUs ran from one shared tile counter: each GPU copies into its own
// copy of a written buffer the tiles the others ran, reading their copies over NVLink
// (peer access). The tiles are the megakernel's: 8x4 over the rows of a launch of several
// rows, else runs of 32 indices.
#pragma once

extern "C" __global__ void lucent_gather_tiles(const unsigned char* owners, unsigned device,
                                               unsigned long long tiles,
                                               lucent::gpu::DeviceCopies copies,
                                               unsigned element_bytes, uint3 size) {
    const bool tiled = LUCENT_GPU_TILES && (size.y > 1 || size.z > 1);  // as the megakernel
    const unsigned tiles_x = (size.x + 7) / 8;
    const unsigned long long rows = (unsigned long long)size.y * size.z;
    const unsigned long long count = rows * size.x;
    const unsigned long long stride = (unsigned long long)gridDim.x * blockDim.x;
    unsigned char* mine = reinterpret_cast<unsigned char*>(copies.base[device]);
    for (unsigned long long i = (unsigned long long)blockIdx.x * blockDim.x + threadIdx.x;
         i < tiles * 32; i += stride) {
        const unsigned long long tile = i / 32;
        const unsigned owner = owners[tile];
        if (owner == device || owner >= lucent::gpu::kGpuMaxDeviceSlots || !copies.base[owner]) continue;
        const unsigned lane = unsigned(i % 32);
        unsigned long long linear;
        if (tiled) {
            const unsigned x = unsigned(tile % tiles_x) * 8 + (lane & 7u);
            const unsigned long long row = (tile / tiles_x) * 4 + (lane >> 3);
            if (x >= size.x || row >= rows) continue;
            linear = row * size.x + x;
        } else {
            linear = i;
            if (linear >= count) continue;
        }
        const unsigned char* from =
            reinterpret_cast<const unsigned char*>(copies.base[owner]) + linear * element_bytes;
        unsigned char* to = mine + linear * element_bytes;
        if (element_bytes % 4 == 0) {
            for (unsigned b = 0; b < element_bytes; b += 4)
                *reinterpret_cast<unsigned*>(to + b) = *reinterpret_cast<const unsigned*>(from + b);
        } else {
            for (unsigned b = 0; b < element_bytes; ++b) to[b] = from[b];
        }
    }
}
