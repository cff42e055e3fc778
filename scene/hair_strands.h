// A procedural head of hair as built-in curves (lucent::GeometryCurves' buffers): strands
// rooted on the upper part of a sphere, each a chain of control points that leaves along the
// surface normal and bends under gravity with a little noise, its radius tapering from root
// to tip. Shared by `lucent bench curves` (the unit head) and the hair sample (a head placed
// in its scene), so both draw the same strands.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lucent/context.h"

namespace lucent::scene {

struct HairStyle {
    unsigned segments = 100000;  // curve segments in all (the last strand may be cut short)
    CurveType type = kCurveCubicBSpline;
    float3 center{0, 0, 0};  // of the head
    float head_radius = 1;   // the strands scale with it: lengths, radii, root height
    unsigned seed = 7;       // of the roots and the noise
};

/// The curves' buffers: control points, a radius per point, each segment's first point.
struct HairStrands {
    std::vector<float3> vertices;
    std::vector<float> radii;
    std::vector<unsigned> segments;
};

/// Segments per strand: every strand has this many, of any curve type.
constexpr unsigned kHairSegmentsPerStrand = 12;

/// The strands of `style`: roots uniform in area on the head above 0.3 of its radius below
/// the centre, 0.2 % of the radius above its surface; 12 segments of 0.07 radii each; radius
/// 0.004 at the root to 0.001 at the tip (of a unit head).
HairStrands make_hair_strands(const HairStyle& style);

/// The curve type called `name`: "linear", "quadratic", "cubic" (B-splines) or
/// "catmull-rom"; none for another name.
std::optional<CurveType> curve_type_named(const std::string& name);
/// The names curve_type_named accepts, in CurveType's order.
const std::vector<std::string>& curve_type_names();

}  // namespace lucent::scene
