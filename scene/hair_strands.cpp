#include "scene/hair_strands.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace lucent::scene {

HairStrands make_hair_strands(const HairStyle& style) {
    HairStrands hair;
    const unsigned points_per_segment = curve_control_points(style.type);
    // Consecutive segments of a strand share all but one control point.
    const unsigned extra = points_per_segment - 1;
    const unsigned strands =
        std::max(1u, (style.segments + kHairSegmentsPerStrand - 1) / kHairSegmentsPerStrand);
    std::mt19937 rng(style.seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), jitter(-1.0f, 1.0f);
    const float step = 0.07f;
    // Grown on a unit head at the origin, then placed: the unit head (the benchmark's) keeps
    // exactly the points it always had.
    const bool placed = style.head_radius != 1.0f || style.center.x != 0.0f ||
                        style.center.y != 0.0f || style.center.z != 0.0f;
    for (unsigned s = 0; s < strands && hair.segments.size() < style.segments; ++s) {
        // A root on the sphere above y = -0.3, uniform in area.
        const float y = -0.3f + 1.3f * unit(rng), phi = 6.2831853f * unit(rng);
        const float ring = std::sqrt(std::max(0.0f, 1.0f - y * y));
        float3 p = make_float3(ring * std::cos(phi), y, ring * std::sin(phi));
        float3 dir = p;
        const unsigned first = unsigned(hair.vertices.size());
        const unsigned points = kHairSegmentsPerStrand + extra;
        for (unsigned k = 0; k < points; ++k) {
            const float3 point = p * 1.002f;
            hair.vertices.push_back(placed ? style.center + style.head_radius * point : point);
            const float along = float(k) / float(points - 1);
            const float radius = 0.004f * (1.0f - 0.75f * along);
            hair.radii.push_back(placed ? style.head_radius * radius : radius);
            dir = normalize(dir + make_float3(0.0f, -0.35f, 0.0f) +
                            0.25f * make_float3(jitter(rng), jitter(rng), jitter(rng)));
            p = p + step * dir;
        }
        for (unsigned k = 0; k < kHairSegmentsPerStrand && hair.segments.size() < style.segments;
             ++k)
            hair.segments.push_back(first + k);
    }
    return hair;
}

const std::vector<std::string>& curve_type_names() {
    static const std::vector<std::string> names = {"linear", "quadratic", "cubic", "catmull-rom"};
    return names;
}

std::optional<CurveType> curve_type_named(const std::string& name) {
    const std::vector<std::string>& names = curve_type_names();
    for (unsigned i = 0; i < names.size(); ++i)
        if (names[i] == name) return CurveType(i);
    return std::nullopt;
}

}  // namespace lucent::scene
