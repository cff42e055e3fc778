// VPL merging of the seed blog: a regular grid of voxels over the scene's bounds; the VPLs in
// a voxel become one at its centre carrying their summed power; empty voxels are skipped.
#pragma once

#include <vector>

#include "samples/radiosity/radiosity_programs.h"

namespace lucent::samples {

struct Bounds3 {
    float3 lo, hi;
};

/// Merges `vpls` (zero-power slots ignored) into a resolution^3 grid over `bounds`. Each
/// merged VPL sits at its voxel's centre with the summed power and the power-weighted mean
/// normal, or none (isotropic) where the normals cancel out. Total power is conserved;
/// VPLs outside `bounds` go to the nearest voxel. Output order: by voxel index.
std::vector<radiosity::Vpl> merge_vpls(const std::vector<radiosity::Vpl>& vpls,
                                       const Bounds3& bounds, unsigned resolution);

}  // namespace lucent::samples
