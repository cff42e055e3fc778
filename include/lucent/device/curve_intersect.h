// Ray/curve intersection for built-in curves (GeometryCurves, OptiX's round curves): a
// segment is the union of the spheres centred on its centre line c(u) with radius r(u), u in
// [0, 1], both interpolated with the segment's basis (linear, uniform quadratic or cubic
// B-spline, Catmull-Rom). Linear segments are cones capped by their end spheres; the cubic
// ones are swept spheres, closed by round ends.
//
// The method. In coordinates where the ray starts at the origin and runs along +z with unit
// speed (ray-centric coordinates, as in Reshetov and Luebke 2018, "Phantom Ray-Hair
// Intersector"), the sphere at u meets the ray where D(u) = r(u)^2 - x(u)^2 - y(u)^2 >= 0,
// over s in [z(u) - sqrt(D), z(u) + sqrt(D)]. Over a connected set of u where D >= 0 the
// union of those intervals is one interval, so the ray enters the curve at the minimum of
// s-(u) = z - sqrt(D) and leaves at the maximum of s+(u) = z + sqrt(D): two 1D problems on
// polynomials, with no singular cone or phantom iteration to start. The segment is cut into
// pieces (8 for cubics); a piece whose convex hull (its exact Bezier form, from the values
// and derivatives at its ends) lies wider than its largest radius from the ray is skipped;
// in the others the largest D is found by Newton's method, the piece's part with D >= 0 is
// bracketed, and the stationary points of s-(u) and s+(u), the roots of
// z' sqrt(D) -+ D'/2, are solved by Newton's method safeguarded by bisection. Pieces whose
// parts touch make one interval. Everything is done in float on both backends, on the
// polynomials of the ray-centric control points, so a thin or distant curve keeps its
// precision (the ray's closest approach is never a difference of large squares).
//
// What is not resolved: two separate parts with D >= 0 inside one piece (a curve folding
// back within an eighth of a segment) count as one; at a joint between segments each
// segment reports its own entry and exit, so a ray that starts inside one segment and
// leaves through the next first meets the first one's end sphere, inside the second.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"

namespace lucent {

/// A control point: position in xyz, radius in w.
using CurvePoint = float4;

/// The segment as a cubic Bezier curve of (position, radius), from its control points in
/// its basis (degree-elevated for linear and quadratic): the Bezier points bound the
/// segment (convex hull), which the other bases' points do not for Catmull-Rom.
LUCENT_HD inline void curve_bezier(unsigned type, const CurvePoint* p, CurvePoint b[4]) {
    const auto mix = [](float4 a, float wa, float4 c, float wc, float4 d, float wd, float4 e,
                        float we) {
        return make_float4(wa * a.x + wc * c.x + wd * d.x + we * e.x,
                           wa * a.y + wc * c.y + wd * d.y + we * e.y,
                           wa * a.z + wc * c.z + wd * d.z + we * e.z,
                           wa * a.w + wc * c.w + wd * d.w + we * e.w);
    };
    const float third = 1.0f / 3.0f, sixth = 1.0f / 6.0f;
    if (type == kCurveLinear) {
        b[0] = p[0];
        b[1] = mix(p[0], 2 * third, p[1], third, p[1], 0, p[1], 0);
        b[2] = mix(p[0], third, p[1], 2 * third, p[1], 0, p[1], 0);
        b[3] = p[1];
    } else if (type == kCurveQuadraticBSpline) {
        // Quadratic Bezier (p0+p1)/2, p1, (p1+p2)/2, elevated to cubic.
        b[0] = mix(p[0], 0.5f, p[1], 0.5f, p[2], 0, p[2], 0);
        b[1] = mix(p[0], sixth, p[1], 5 * sixth, p[2], 0, p[2], 0);
        b[2] = mix(p[0], 0, p[1], 5 * sixth, p[2], sixth, p[2], 0);
        b[3] = mix(p[0], 0, p[1], 0.5f, p[2], 0.5f, p[2], 0);
    } else if (type == kCurveCubicBSpline) {
        b[0] = mix(p[0], sixth, p[1], 4 * sixth, p[2], sixth, p[3], 0);
        b[1] = mix(p[0], 0, p[1], 2 * third, p[2], third, p[3], 0);
        b[2] = mix(p[0], 0, p[1], third, p[2], 2 * third, p[3], 0);
        b[3] = mix(p[0], 0, p[1], sixth, p[2], 4 * sixth, p[3], sixth);
    } else {  // Catmull-Rom: through p1 and p2 with tangents (p2 - p0) / 2 and (p3 - p1) / 2
        b[0] = p[1];
        b[1] = mix(p[0], -sixth, p[1], 1, p[2], sixth, p[3], 0);
        b[2] = mix(p[0], 0, p[1], sixth, p[2], 1, p[3], -sixth);
        b[3] = p[2];
    }
}

/// Segment `first`'s control points (curve_control_points(type) consecutive vertices and
/// radii from index `first`) as cubic Bezier points.
LUCENT_HD inline void load_curve_segment(unsigned type, const float3* vertices,
                                         const float* radii, unsigned first, CurvePoint b[4]) {
    CurvePoint p[4];
    const unsigned n = curve_control_points(type);
    for (unsigned i = 0; i < 4; ++i) {
        const unsigned k = first + (i < n ? i : n - 1);
        p[i] = make_float4(vertices[k], radii[k]);
    }
    curve_bezier(type, p, b);
}

/// One intersection of a ray with a curve segment: the ray parameter, the segment's
/// parameter u, the unit normal (from the sphere at u through the hit: outward), and
/// whether the ray enters the curve there (1) or leaves it (0).
struct CurveHit {
    float t, u;
    float3 normal;
    unsigned entering;
};

namespace curve_detail {

/// A cubic in power form, a0 + a1 u + a2 u^2 + a3 u^3, with its value and first two
/// derivatives.
struct Cubic {
    float a0, a1, a2, a3;
    LUCENT_HD float at(float u) const { return a0 + u * (a1 + u * (a2 + u * a3)); }
    LUCENT_HD float d1(float u) const { return a1 + u * (2.0f * a2 + u * 3.0f * a3); }
    LUCENT_HD float d2(float u) const { return 2.0f * a2 + u * 6.0f * a3; }
};

LUCENT_HD inline Cubic power_form(float b0, float b1, float b2, float b3) {
    return Cubic{b0, 3.0f * (b1 - b0), 3.0f * (b2 - 2.0f * b1 + b0),
                 b3 - 3.0f * b2 + 3.0f * b1 - b0};
}

/// The segment in ray-centric coordinates: x, y across the ray, z along it, w the radius.
struct RayCentric {
    Cubic x, y, z, w;
};

/// The quantities of the sphere at u that the search reads.
struct Sample {
    float z, dz, ddz;
    float D, dD, ddD;  // r^2 - x^2 - y^2 and its derivatives
};

LUCENT_HD inline Sample sample(const RayCentric& c, float u) {
    const float x = c.x.at(u), dx = c.x.d1(u), ddx = c.x.d2(u);
    const float y = c.y.at(u), dy = c.y.d1(u), ddy = c.y.d2(u);
    const float w = c.w.at(u), dw = c.w.d1(u), ddw = c.w.d2(u);
    Sample s;
    s.z = c.z.at(u);
    s.dz = c.z.d1(u);
    s.ddz = c.z.d2(u);
    s.D = (w - x) * (w + x) - y * y;
    s.dD = 2.0f * (w * dw - x * dx - y * dy);
    s.ddD = 2.0f * (dw * dw + w * ddw - dx * dx - x * ddx - dy * dy - y * ddy);
    return s;
}

/// The ray's entry (sign -1) or exit (+1) distance for the sphere at u: z -+ sqrt(D).
LUCENT_HD inline float side_distance(const Sample& s, float sign) {
    return s.z + sign * sqrtf(lc_max(s.D, 0.0f));
}

/// ds/du of side_distance times sqrt(D) (finite where D = 0): z' sqrt(D) + sign D'/2, and its
/// derivative for Newton's method.
LUCENT_HD inline void side_slope(const RayCentric& c, float u, float sign, float& f,
                                 float& df) {
    const Sample s = sample(c, u);
    const float root = sqrtf(lc_max(s.D, 0.0f));
    f = s.dz * root + sign * 0.5f * s.dD;
    df = s.ddz * root + (root > 0.0f ? s.dz * s.dD / (2.0f * root) : 0.0f) +
         sign * 0.5f * s.ddD;
}

/// A root of fn between `neg` (fn < 0) and `pos` (fn > 0), either order: Newton's method
/// kept inside the bracket, bisection where a step would leave it.
template <class Fn>
LUCENT_HD inline float bracketed_root(const Fn& fn, float neg, float pos) {
    float u = 0.5f * (neg + pos);
    for (int i = 0; i < 32; ++i) {
        float f, df;
        fn(u, f, df);
        if (f == 0.0f) return u;
        if (f < 0.0f)
            neg = u;
        else
            pos = u;
        const float lo = lc_min(neg, pos), hi = lc_max(neg, pos);
        float next = u - f / df;
        if (!(next > lo && next < hi)) next = 0.5f * (lo + hi);  // also a zero or NaN slope
        if (fabsf(next - u) <= 1e-7f || hi - lo <= 1e-7f) return next;
        u = next;
    }
    return u;
}

/// The u of the largest D on [a, b]: the best of five even samples, then the root of D'
/// beside it where D' falls through zero (Newton's method in the bracket), so that a
/// grazing part between two samples is found.
LUCENT_HD inline float peak(const RayCentric& c, float a, float b, float& d_peak) {
    constexpr int kSamples = 5;
    float at[kSamples], slope[kSamples];
    int best = 0;
    d_peak = 0.0f;
    for (int j = 0; j < kSamples; ++j) {
        at[j] = j + 1 == kSamples ? b : a + (b - a) * (float(j) / float(kSamples - 1));
        const Sample s = sample(c, at[j]);
        slope[j] = -s.dD;  // negative -> positive where D has a maximum
        if (j == 0 || s.D > d_peak) best = j, d_peak = s.D;
    }
    int neg = -1, pos = -1;
    if (slope[best] < 0.0f && best + 1 < kSamples && slope[best + 1] > 0.0f)
        neg = best, pos = best + 1;
    else if (slope[best] > 0.0f && best > 0 && slope[best - 1] < 0.0f)
        neg = best - 1, pos = best;
    if (neg < 0) return at[best];
    const auto falling = [&](float u, float& f, float& df) {
        const Sample s = sample(c, u);
        f = -s.dD;
        df = -s.ddD;
    };
    const float u = bracketed_root(falling, at[neg], at[pos]);
    const float d = sample(c, u).D;
    if (d > d_peak) {
        d_peak = d;
        return u;
    }
    return at[best];
}

/// On [lo, hi], where D >= 0: the u where side_distance is smallest (sign -1, the entry) or
/// largest (+1, the exit). The best of five even samples, then the stationary point beside
/// it where the slope changes sign (falling then rising for the entry, the reverse for the
/// exit), so that a bend inside the part that turns the slope twice is not missed.
LUCENT_HD inline float extreme(const RayCentric& c, float lo, float hi, float sign) {
    constexpr int kSamples = 5;
    float slope[kSamples], at[kSamples];
    int best = 0;
    float best_s = 0.0f;
    for (int j = 0; j < kSamples; ++j) {
        at[j] = j + 1 == kSamples ? hi : lo + (hi - lo) * (float(j) / float(kSamples - 1));
        float unused;
        side_slope(c, at[j], sign, slope[j], unused);
        slope[j] *= -sign;  // both searches then look for negative -> positive
        const float s = -sign * side_distance(sample(c, at[j]), sign);
        if (j == 0 || s < best_s) best = j, best_s = s;
    }
    int neg = -1, pos = -1;
    if (slope[best] < 0.0f && best + 1 < kSamples && slope[best + 1] > 0.0f)
        neg = best, pos = best + 1;
    else if (slope[best] > 0.0f && best > 0 && slope[best - 1] < 0.0f)
        neg = best - 1, pos = best;
    if (neg < 0) return at[best];
    const auto flipped = [&](float u, float& f, float& df) {
        side_slope(c, u, sign, f, df);
        f *= -sign;
        df *= -sign;
    };
    return bracketed_root(flipped, at[neg], at[pos]);
}

}  // namespace curve_detail

/// How many pieces the search cuts a segment of this type into: a linear segment (a
/// quadratic D) has one part with D >= 0 at most, and two pieces only so that it has two
/// BVH references; the others bend.
LUCENT_HD inline int curve_pieces(unsigned type) {
    return type == kCurveLinear ? 2 : type == kCurveQuadraticBSpline ? 4 : 8;
}

/// How many references to a segment of this type the BVH holds, each with the box of its
/// range of u (curve_pieces / curve_references pieces): a slanted strand's one box would be
/// mostly empty, and every ray entering it would pay the segment's test.
LUCENT_HD inline unsigned curve_references(unsigned type) {
    return type == kCurveLinear ? 2u : type == kCurveQuadraticBSpline ? 2u : 4u;
}

/// The Bezier points of the segment's part over [u0, u1] (its hull), from the values and
/// slopes at the ends.
LUCENT_HD inline void curve_part_hull(const CurvePoint b[4], float u0, float u1,
                                      CurvePoint out[4]) {
    const auto at = [&](float u, float4& value, float4& slope) {
        const float s = 1.0f - u;
        const float w0 = s * s * s, w1 = 3.0f * u * s * s, w2 = 3.0f * u * u * s, w3 = u * u * u;
        const float d0 = -3.0f * s * s, d1 = 3.0f * s * s - 6.0f * u * s,
                    d2 = 6.0f * u * s - 3.0f * u * u, d3 = 3.0f * u * u;
        value = make_float4(w0 * b[0].x + w1 * b[1].x + w2 * b[2].x + w3 * b[3].x,
                            w0 * b[0].y + w1 * b[1].y + w2 * b[2].y + w3 * b[3].y,
                            w0 * b[0].z + w1 * b[1].z + w2 * b[2].z + w3 * b[3].z,
                            w0 * b[0].w + w1 * b[1].w + w2 * b[2].w + w3 * b[3].w);
        slope = make_float4(d0 * b[0].x + d1 * b[1].x + d2 * b[2].x + d3 * b[3].x,
                            d0 * b[0].y + d1 * b[1].y + d2 * b[2].y + d3 * b[3].y,
                            d0 * b[0].z + d1 * b[1].z + d2 * b[2].z + d3 * b[3].z,
                            d0 * b[0].w + d1 * b[1].w + d2 * b[2].w + d3 * b[3].w);
    };
    float4 v0, s0, v1, s1;
    at(u0, v0, s0);
    at(u1, v1, s1);
    const float h = (u1 - u0) * (1.0f / 3.0f);
    out[0] = v0;
    out[1] = v0 + h * s0;
    out[2] = v1 + (-h) * s1;
    out[3] = v1;
}

/// Where a ray meets one BVH reference's range of a segment: up to two parts of u with
/// D >= 0, each with its entry, and the ranges its exit is searched over when it is needed
/// (curve_part_hit): a ray whose entry is accepted never needs the exit.
struct CurveParts {
    curve_detail::RayCentric c;
    float3 e1, e2, d;  // the ray-centric frame
    float speed, u_first, u_last;
    int count;
    struct Part {
        float u_in, s_in;
        float lo[2], hi[2];  // the part's range in each piece it spans
        int ranges;
    } part[2];
};

/// Finds the parts of reference `reference` (below curve_references(type)) of the segment
/// given by its cubic Bezier points (curve_bezier) that the ray origin + t direction passes
/// through, with their entries; returns how many (0 also for a ray that misses the
/// reference's hull or the interval (tmin, tmax)). The direction need not be unit length.
LUCENT_HD inline int find_curve_parts(float3 origin, float3 direction, unsigned type,
                                      const CurvePoint b[4], unsigned reference, float tmin,
                                      float tmax, CurveParts& q) {
    using namespace curve_detail;
    q.count = 0;
    const float speed = length(direction);
    if (!(speed > 0.0f) || !(speed < 3.0e38f)) return 0;
    const float3 d = direction * (1.0f / speed);
    // An orthonormal frame around d (Duff et al. 2017, "Building an Orthonormal Basis,
    // Revisited").
    const float sign = d.z >= 0.0f ? 1.0f : -1.0f;
    const float ka = -1.0f / (sign + d.z), kb = d.x * d.y * ka;
    const float3 e1 = make_float3(1.0f + sign * d.x * d.x * ka, sign * kb, -sign * d.x);
    const float3 e2 = make_float3(kb, sign + d.y * d.y * ka, -d.y);

    float px[4], py[4], pz[4], pw[4];
    for (int i = 0; i < 4; ++i) {
        const float3 r = make_float3(b[i]) - origin;
        px[i] = dot(r, e1);
        py[i] = dot(r, e2);
        pz[i] = dot(r, d);
        pw[i] = b[i].w;
    }
    // The segment's Bezier points hold it: skip it when their hull, widened by their largest
    // radius, misses the ray or lies outside the interval.
    float x_lo = px[0], x_hi = px[0], y_lo = py[0], y_hi = py[0], z_lo = pz[0], z_hi = pz[0];
    float w_max = fabsf(pw[0]);
    for (int i = 1; i < 4; ++i) {
        x_lo = lc_min(x_lo, px[i]), x_hi = lc_max(x_hi, px[i]);
        y_lo = lc_min(y_lo, py[i]), y_hi = lc_max(y_hi, py[i]);
        z_lo = lc_min(z_lo, pz[i]), z_hi = lc_max(z_hi, pz[i]);
        w_max = lc_max(w_max, fabsf(pw[i]));
    }
    if (x_lo > w_max || x_hi < -w_max || y_lo > w_max || y_hi < -w_max ||
        z_hi + w_max < tmin * speed || z_lo - w_max > tmax * speed)
        return 0;
    RayCentric& c = q.c;
    c.x = power_form(px[0], px[1], px[2], px[3]);
    c.y = power_form(py[0], py[1], py[2], py[3]);
    c.z = power_form(pz[0], pz[1], pz[2], pz[3]);
    c.w = power_form(pw[0], pw[1], pw[2], pw[3]);
    q.e1 = e1, q.e2 = e2, q.d = d, q.speed = speed;
    const int per_reference = curve_pieces(type) / int(curve_references(type));
    const int pieces = curve_pieces(type), first_piece = int(reference) * per_reference;
    q.u_first = float(first_piece) / float(pieces);
    q.u_last = first_piece + per_reference == pieces
                   ? 1.0f
                   : float(first_piece + per_reference) / float(pieces);

    bool open = false;  // the current part reaches the current piece's start
    CurveParts::Part current{};
    const auto finish_part = [&]() {
        if (q.count < 2) q.part[q.count++] = current;
        open = false;
    };
    float a = q.u_first;
    float ax = c.x.at(a), ay = c.y.at(a), aw = c.w.at(a);
    float adx = c.x.d1(a), ady = c.y.d1(a), adw = c.w.d1(a);
    for (int k = first_piece; k < first_piece + per_reference; ++k) {
        const float e = k + 1 == pieces ? 1.0f : float(k + 1) / float(pieces);
        const float h = (e - a) * (1.0f / 3.0f);
        const float ex = c.x.at(e), ey = c.y.at(e), ew = c.w.at(e);
        const float edx = c.x.d1(e), edy = c.y.d1(e), edw = c.w.d1(e);
        // The piece's Bezier points from its ends' values and slopes: its hull across the
        // ray and its largest radius. A piece with some D >= 0 is never skipped: its point
        // lies in the hull, within its radius of the ray.
        const float hx[4] = {ax, ax + h * adx, ex - h * edx, ex};
        const float hy[4] = {ay, ay + h * ady, ey - h * edy, ey};
        const float hw[4] = {aw, aw + h * adw, ew - h * edw, ew};
        float px_lo = hx[0], px_hi = hx[0], py_lo = hy[0], py_hi = hy[0], pw_max = fabsf(hw[0]);
        for (int i = 1; i < 4; ++i) {
            px_lo = lc_min(px_lo, hx[i]);
            px_hi = lc_max(px_hi, hx[i]);
            py_lo = lc_min(py_lo, hy[i]);
            py_hi = lc_max(py_hi, hy[i]);
            pw_max = lc_max(pw_max, fabsf(hw[i]));
        }
        float d_peak = -1.0f, u_peak = a;
        if (px_lo <= pw_max && px_hi >= -pw_max && py_lo <= pw_max && py_hi >= -pw_max)
            u_peak = peak(c, a, e, d_peak);
        if (d_peak > 0.0f) {
            const auto D = [&](float u, float& f, float& df) {
                const Sample s = sample(c, u);
                f = s.D;
                df = s.dD;
            };
            const float lo = sample(c, a).D >= 0.0f ? a : bracketed_root(D, a, u_peak);
            const bool reaches_end = sample(c, e).D >= 0.0f;
            const float hi = reaches_end ? e : bracketed_root(D, e, u_peak);
            const float u_in = extreme(c, lo, hi, -1.0f);
            const float s_in = side_distance(sample(c, u_in), -1.0f);
            if (open && lo == a && current.ranges < 2) {  // the part continues: widen it
                if (s_in < current.s_in) current.u_in = u_in, current.s_in = s_in;
            } else {
                if (open) finish_part();
                current.u_in = u_in, current.s_in = s_in, current.ranges = 0;
            }
            current.lo[current.ranges] = lo;
            current.hi[current.ranges] = hi;
            ++current.ranges;
            open = true;
            if (!reaches_end) finish_part();
        } else if (open) {
            finish_part();
        }
        a = e;
        ax = ex, ay = ey, aw = ew, adx = edx, ady = edy, adw = edw;
    }
    if (open) finish_part();
    return q.count;
}

/// Part i's entry (side 0) or exit (side 1) as a hit, the exit searched now; false when it
/// lies outside (tmin, tmax), or at the reference's inner end while the side distance
/// still improves (falls for an entry, rises for an exit) across it: it belongs to the
/// neighbouring reference, so a tube seen through several references is hit once. Where it
/// is flat there, the reference after the end keeps it (both compute the same slope at the
/// same u).
LUCENT_HD inline bool curve_part_hit(const CurveParts& q, int i, int side, float tmin,
                                     float tmax, CurveHit& hit) {
    using namespace curve_detail;
    const RayCentric& c = q.c;
    const CurveParts::Part& part = q.part[i];
    float u = part.u_in, s = part.s_in;
    if (side == 1) {
        for (int r = 0; r < part.ranges; ++r) {
            const float ur = extreme(c, part.lo[r], part.hi[r], 1.0f);
            const float sr = side_distance(sample(c, ur), 1.0f);
            if (r == 0 || sr > s) u = ur, s = sr;
        }
    }
    if (!(s > tmin * q.speed && s < tmax * q.speed)) return false;
    const float sign = side == 0 ? -1.0f : 1.0f;
    if ((u == q.u_first && q.u_first > 0.0f) || (u == q.u_last && q.u_last < 1.0f)) {
        float slope, unused;
        side_slope(c, u, sign, slope, unused);
        if (u == q.u_first ? sign * -slope > 0.0f : sign * slope >= 0.0f) return false;
    }
    // The normal from the sphere at u through the hit, in ray-centric coordinates, divided
    // by the radius first (a thin curve's squared offset would underflow).
    const float w = fabsf(c.w.at(u));
    const float inv = w > 0.0f ? 1.0f / w : 1.0f;
    const float nx = -c.x.at(u) * inv, ny = -c.y.at(u) * inv, nz = (s - c.z.at(u)) * inv;
    float3 n = nx * q.e1 + ny * q.e2 + nz * q.d;
    n = n * (1.0f / length(n));
    hit = CurveHit{s / q.speed, u, n, side == 0 ? 1u : 0u};
    return true;
}

/// The intersections of the ray origin + t direction, t in (tmin, tmax), with the range of
/// a segment that BVH reference `reference` covers (find_curve_parts), nearest first: for
/// each part the ray passes through, its entry and its exit. Writes up to four; returns how
/// many.
LUCENT_HD inline int intersect_curve(float3 origin, float3 direction, unsigned type,
                                     const CurvePoint b[4], unsigned reference, float tmin,
                                     float tmax, CurveHit hits[4]) {
    CurveParts q;
    const int parts = find_curve_parts(origin, direction, type, b, reference, tmin, tmax, q);
    int count = 0;
    for (int i = 0; i < parts; ++i)
        for (int side = 0; side < 2; ++side) {
            CurveHit hit;
            if (!curve_part_hit(q, i, side, tmin, tmax, hit)) continue;
            int j = count++;
            for (; j > 0 && hits[j - 1].t > hit.t; --j) hits[j] = hits[j - 1];
            hits[j] = hit;
        }
    return count;
}

}  // namespace lucent
