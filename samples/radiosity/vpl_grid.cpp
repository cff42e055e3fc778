#include "samples/radiosity/vpl_grid.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace lucent::samples {

namespace {

unsigned cell_of(float x, float lo, float hi, unsigned resolution) {
    const float t = hi > lo ? (x - lo) / (hi - lo) : 0.0f;
    const int cell = int(std::floor(t * float(resolution)));
    return unsigned(std::clamp(cell, 0, int(resolution) - 1));
}

float luminance(float3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

}  // namespace

std::vector<radiosity::Vpl> merge_vpls(const std::vector<radiosity::Vpl>& vpls,
                                       const Bounds3& bounds, unsigned resolution) {
    struct Cell {
        float3 power{0, 0, 0};
        float3 weighted_normal{0, 0, 0};
    };
    std::map<unsigned, Cell> cells;  // sparse: most voxels of a room are empty
    for (const radiosity::Vpl& vpl : vpls) {
        if (max_component(vpl.power) <= 0.0f) continue;
        const unsigned x = cell_of(vpl.position.x, bounds.lo.x, bounds.hi.x, resolution);
        const unsigned y = cell_of(vpl.position.y, bounds.lo.y, bounds.hi.y, resolution);
        const unsigned z = cell_of(vpl.position.z, bounds.lo.z, bounds.hi.z, resolution);
        Cell& cell = cells[(z * resolution + y) * resolution + x];
        cell.power += vpl.power;
        cell.weighted_normal += vpl.normal * luminance(vpl.power);
    }
    const float3 size = (bounds.hi - bounds.lo) * (1.0f / float(resolution));
    std::vector<radiosity::Vpl> merged;
    merged.reserve(cells.size());
    for (const auto& [index, cell] : cells) {
        const unsigned x = index % resolution, y = (index / resolution) % resolution,
                       z = index / (resolution * resolution);
        const float3 centre =
            bounds.lo + size * make_float3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f);
        const float length_n = length(cell.weighted_normal);
        // Normals that mostly cancel (a corner's walls) leave no direction to prefer.
        const float total = luminance(cell.power);
        const float3 normal = length_n > 0.5f * total && length_n > 0.0f
                                  ? cell.weighted_normal / length_n
                                  : make_float3(0.0f);
        merged.push_back({centre, normal, cell.power});
    }
    return merged;
}

}  // namespace lucent::samples
