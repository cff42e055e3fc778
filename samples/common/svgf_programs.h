// Spatiotemporal variance-guided filtering (Schied, Kaplanyan, Wyman, Patney, Chaitanya,
// Burgess, Liu, Dachsbacher, Lefohn and Salvi 2017, "Spatiotemporal Variance-Guided
// Filtering: Real-Time Reconstruction for Path-Traced Global Illumination"): the temporal
// variant of the à-trous denoiser (samples/common/atrous_programs.h) for the viewer's moving
// camera. Four programs, each one launch over the image:
//   svgf_temporal  §4.1: the frame's illumination (colour / albedo) blended with its history,
//                  found by reprojecting the pixel's surface point into the previous camera
//                  and kept only where the surface there is the same (instance, normal and
//                  distance to the tangent plane); the first and second moments of the
//                  luminance are blended the same way.
//   svgf_variance  §4.2: each pixel's luminance variance from its moments, or, for a history
//                  shorter than 4 frames, from the moments of its 7x7 neighbourhood.
//   svgf_atrous    §4.3: a wavelet pass (the 5x5 B3 kernel, taps 2^i apart) whose weights are
//                  the edge-stopping functions of Eq. 3-5 on depth (sigma_z), normal
//                  (sigma_n) and luminance (sigma_l, against the 3x3-blurred standard
//                  deviation); it filters the variance with the squared weights (Eq. 2).
//   svgf_keep      the frame's integrated colour, moments and G-buffer become the next
//                  frame's history.
//
// Departures from the paper, and why: the history colour is the temporally integrated
// colour, not the first wavelet pass's output (the paper's choice against lag), so that a
// resting camera's history is exactly the progressive mean; a resting camera blends with
// alpha = 1/n, never the paper's floor of 0.2, so it converges as the viewer's progressive
// accumulation does; and the variance that steers the filter is that of the integrated mean,
// the moments' variance times sum(w_i^2) of the blend's weights (1/n for a plain mean), so the
// filter fades as the history converges. The depth test of §4.1 and w_z of Eq. 3 use the
// distance of q's point to p's tangent plane in units of p's pixel footprint (as the à-trous
// filter does), not a screen-space depth gradient: one tolerance for any scene scale.
#pragma once

#include "lucent/device.h"
#include "samples/common/atrous_programs.h"
#include "samples/common/camera.h"

namespace sample_svgf {

/// The module of the temporal denoiser's programs (lucent/device/module.h).
LUCENT_MODULE(sample_svgf)

/// The frame's parameters: a 1-element buffer uploaded before the frame's launches.
struct SvgfFrame {
    sample_common::PinholeCamera previous;  // the camera of the history
    float footprint;     // a pixel's width at depth 1 in this frame: 2 |V| / height
    float alpha_colour;  // the blend's floor while the camera moves (the paper's 0.2)
    float alpha_moments;
    float normal_cos;       // reprojection: the history's normal within this angle's cosine
    float plane_tolerance;  // ... and its point this many footprints from the tangent plane
    unsigned has_history;   // 0: the first frame, or after a reset
    unsigned resting;       // 1: the camera did not move: a plain mean (alpha = 1/n)
};

/// One wavelet pass's parameters (uploaded before its launch).
struct SvgfPass {
    unsigned step;  // 2^i
    unsigned last;  // 1: multiply the illumination back by the albedo
    float sigma_z, sigma_n, sigma_l;
    float footprint;
};

LUCENT_HD inline float luminance(float3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

LUCENT_HD inline float3 rgb(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

/// Where world point x lies in `camera`'s image of n pixels, in pixels whose centres are at
/// integer coordinates (row 0 at the top); false behind the camera.
LUCENT_HD inline bool project(const sample_common::PinholeCamera& camera, float3 x, uint3 n,
                              float& px, float& py) {
    const float3 d = x - camera.eye;
    const float w = dot(d, camera.W) / dot(camera.W, camera.W);
    if (w <= 0.0f) return false;
    const float sx = dot(d, camera.U) / dot(camera.U, camera.U) / w;
    const float sy = dot(d, camera.V) / dot(camera.V, camera.V) / w;
    px = (sx + 1.0f) * 0.5f * float(n.x) - 0.5f;
    py = (1.0f - sy) * 0.5f * float(n.y) - 0.5f;
    return true;
}

/// The distance from q's point to p's tangent plane, in units of p's pixel footprint.
LUCENT_HD inline float plane_distance(float3 np, float3 xp, float unit, float4 xq) {
    return fabsf(dot(np, make_float3(xq.x, xq.y, xq.z) - xp)) / lc_max(unit, 1e-20f);
}

struct TemporalRecord {
    lucent::BufferView<const SvgfFrame> svgf_frame;  // one element
    lucent::BufferView<const float4> svgf_colour;    // the frame's noisy colour
    lucent::BufferView<const float4> aov_albedo, aov_normal, aov_position;
    lucent::BufferView<const float4> history_normal, history_position;
    lucent::BufferView<const float4> history_colour;   // illumination; w = history length
    lucent::BufferView<const float4> history_moments;  // m1, m2, sum w^2
    lucent::BufferView<float4> integrated_colour;      // as history_colour
    lucent::BufferView<float4> integrated_moments;     // as history_moments
};
LUCENT_RECORD(TemporalRecord, svgf_frame, svgf_colour, aov_albedo, aov_normal, aov_position,
              history_normal, history_position, history_colour, history_moments, integrated_colour,
              integrated_moments)

/// §4.1 at pixel p: the history at p's surface point in the previous frame, a bilinear blend
/// of the four pixels around it that pass the consistency test, then the exponential
/// moving average (Eq. 1).
LUCENT_HD inline void temporal_pixel(const TemporalRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const SvgfFrame frame = rec.svgf_frame[0u];
    const float4 ap = rec.aov_albedo[p], np4 = rec.aov_normal[p], xp4 = rec.aov_position[p];
    const bool covered = ap.w > 0.5f;
    const float3 illumination = rgb(rec.svgf_colour[p]) / sample_atrous::demodulation(ap);
    const float l = luminance(illumination);

    float3 colour = make_float3(0.0f);
    float m1 = 0.0f, m2 = 0.0f, squares = 0.0f, length = 0.0f, weights = 0.0f;
    float px = 0.0f, py = 0.0f;
    if (frame.has_history && covered &&
        project(frame.previous, make_float3(xp4.x, xp4.y, xp4.z), n, px, py)) {
        const float3 np = rgb(np4), xp = make_float3(xp4.x, xp4.y, xp4.z);
        const float unit = frame.footprint * xp4.w;
        const float fx = floorf(px), fy = floorf(py);
        for (int t = 0; t < 4; ++t) {
            const int qx = int(fx) + (t & 1), qy = int(fy) + (t >> 1);
            if (qx < 0 || qy < 0 || qx >= int(n.x) || qy >= int(n.y)) continue;
            const uint2 q = make_uint2(unsigned(qx), unsigned(qy));
            const float4 nq = rec.history_normal[q];
            if (nq.w != np4.w) continue;  // another instance, or the background (-1)
            if (dot(np, rgb(nq)) < frame.normal_cos) continue;
            if (plane_distance(np, xp, unit, rec.history_position[q]) > frame.plane_tolerance)
                continue;
            const float w =
                ((t & 1) ? px - fx : 1.0f - (px - fx)) * ((t >> 1) ? py - fy : 1.0f - (py - fy));
            const float4 c = rec.history_colour[q], m = rec.history_moments[q];
            colour += w * rgb(c);
            length += w * c.w;
            m1 += w * m.x;
            m2 += w * m.y;
            squares += w * m.z;
            weights += w;
        }
    }
    if (weights > 1e-4f) {
        const float inv = 1.0f / weights;
        const float n_frames = length * inv + 1.0f;
        const float mean = 1.0f / n_frames;  // the cumulative mean's weight
        const float a = frame.resting ? mean : lc_max(mean, frame.alpha_colour);
        const float am = frame.resting ? mean : lc_max(mean, frame.alpha_moments);
        colour = colour * inv * (1.0f - a) + illumination * a;
        m1 = m1 * inv * (1.0f - am) + l * am;
        m2 = m2 * inv * (1.0f - am) + l * l * am;
        // The blend's sum of squared weights: the variance of the mean over that of a sample.
        squares = squares * inv * (1.0f - a) * (1.0f - a) + a * a;
        rec.integrated_colour[p] = make_float4(colour, n_frames);
        rec.integrated_moments[p] = make_float4(m1, m2, squares, 0.0f);
    } else {
        // No consistent history (disoccluded, off-screen, or the first frame): restart.
        rec.integrated_colour[p] = make_float4(illumination, 1.0f);
        rec.integrated_moments[p] = make_float4(l, l * l, 1.0f, 0.0f);
    }
}

LUCENT_RAY_GENERATION(svgf_temporal, sample_svgf::TemporalRecord) {
    sample_svgf::temporal_pixel(rec);
}

/// The edge-stopping weight of Eq. 3 and 4 (depth and normal) between p and q, `step`
/// pixels apart per tap: the depth term's tolerance grows with the distance, as the paper's
/// |grad z . (p - q)| does.
LUCENT_HD inline float geometry_weight(float3 np, float3 xp, float unit, float4 nq, float4 xq,
                                       float step, float sigma_z, float sigma_n) {
    const float wz = expf(-plane_distance(np, xp, unit, xq) / lc_max(sigma_z * step, 1e-6f));
    const float wn = powf(lc_max(0.0f, dot(np, rgb(nq))), sigma_n);
    return wz * wn;
}

struct VarianceRecord {
    lucent::BufferView<const SvgfFrame> svgf_frame;
    lucent::BufferView<const float4> aov_albedo, aov_normal, aov_position;
    lucent::BufferView<const float4> integrated_colour, integrated_moments;
    lucent::BufferView<float4> svgf_output;  // illumination; w = variance
};
LUCENT_RECORD(VarianceRecord, svgf_frame, aov_albedo, aov_normal, aov_position, integrated_colour,
              integrated_moments, svgf_output)

/// §4.2 at pixel p: the variance of the integrated luminance, from the temporal moments once
/// 4 frames are integrated, else from the moments over a 7x7 neighbourhood of the same
/// surface (weighted by depth and normal).
LUCENT_HD inline void variance_pixel(const VarianceRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const float4 c = rec.integrated_colour[p], m = rec.integrated_moments[p];
    const float4 np4 = rec.aov_normal[p], xp4 = rec.aov_position[p];
    if (rec.aov_albedo[p].w <= 0.5f) {
        rec.svgf_output[p] = make_float4(rgb(c), 0.0f);
        return;
    }
    float variance = lc_max(0.0f, m.y - m.x * m.x);
    if (c.w < 4.0f) {
        const SvgfFrame frame = rec.svgf_frame[0u];
        const float3 np = rgb(np4), xp = make_float3(xp4.x, xp4.y, xp4.z);
        const float unit = frame.footprint * xp4.w;
        float m1 = 0.0f, m2 = 0.0f, weights = 0.0f;
        for (int dy = -3; dy <= 3; ++dy)
            for (int dx = -3; dx <= 3; ++dx) {
                const int qx = int(p.x) + dx, qy = int(p.y) + dy;
                if (qx < 0 || qy < 0 || qx >= int(n.x) || qy >= int(n.y)) continue;
                const uint2 q = make_uint2(unsigned(qx), unsigned(qy));
                if (rec.aov_albedo[q].w <= 0.5f) continue;
                const float w = geometry_weight(np, xp, unit, rec.aov_normal[q],
                                                rec.aov_position[q], 1.0f, 1.0f, 128.0f);
                const float4 mq = rec.integrated_moments[q];
                m1 += w * mq.x;
                m2 += w * mq.y;
                weights += w;
            }
        // The centre's weight is 1, so weights >= 1.
        m1 /= weights;
        variance = lc_max(0.0f, m2 / weights - m1 * m1);
    }
    rec.svgf_output[p] = make_float4(rgb(c), variance * m.z);
}

LUCENT_RAY_GENERATION(svgf_variance, sample_svgf::VarianceRecord) {
    sample_svgf::variance_pixel(rec);
}

struct AtrousRecord {
    lucent::BufferView<const SvgfPass> svgf_pass;  // one element
    lucent::BufferView<const float4> aov_albedo, aov_normal, aov_position;
    lucent::BufferView<const float4> svgf_input;  // illumination; w = variance
    lucent::BufferView<float4> svgf_output;
};
LUCENT_RECORD(AtrousRecord, svgf_pass, aov_albedo, aov_normal, aov_position, svgf_input,
              svgf_output)

/// The variance at p blurred by a 3x3 Gaussian (§4.3: it makes the luminance weight robust).
LUCENT_HD inline float blurred_variance(const AtrousRecord& rec, uint2 p, uint3 n) {
    const float kernel[2] = {0.25f, 0.125f};  // centre 1/4, sides 1/8, corners 1/16
    float sum = 0.0f, weights = 0.0f;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int qx = int(p.x) + dx, qy = int(p.y) + dy;
            if (qx < 0 || qy < 0 || qx >= int(n.x) || qy >= int(n.y)) continue;
            const float w = kernel[dx != 0] * kernel[dy != 0] * 4.0f;
            sum += w * rec.svgf_input[make_uint2(unsigned(qx), unsigned(qy))].w;
            weights += w;
        }
    return sum / weights;
}

/// §4.3 at pixel p: one wavelet pass with the weights of Eq. 3-5 (Eq. 1 and 2 of the
/// paper's filter: colour by w, variance by w^2).
LUCENT_HD inline void atrous_pixel(const AtrousRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const SvgfPass pass = rec.svgf_pass[0u];
    const float4 cp = rec.svgf_input[p], ap = rec.aov_albedo[p];
    if (ap.w <= 0.5f) {  // the background is not filtered (it has no geometry to guide it)
        rec.svgf_output[p] = make_float4(rgb(cp), pass.last ? 1.0f : 0.0f);
        return;
    }
    const float4 np4 = rec.aov_normal[p], xp4 = rec.aov_position[p];
    const float3 np = rgb(np4), xp = make_float3(xp4.x, xp4.y, xp4.z);
    const float unit = pass.footprint * xp4.w;
    const float lp = luminance(rgb(cp));
    const float sigma = pass.sigma_l * sqrtf(blurred_variance(rec, p, n)) + 1e-10f;
    const float kernel[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
    float3 sum = make_float3(0.0f);
    float variance = 0.0f, weights = 0.0f;
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            const int qx = int(p.x) + dx * int(pass.step), qy = int(p.y) + dy * int(pass.step);
            if (qx < 0 || qy < 0 || qx >= int(n.x) || qy >= int(n.y)) continue;
            const uint2 q = make_uint2(unsigned(qx), unsigned(qy));
            if (rec.aov_albedo[q].w <= 0.5f) continue;
            const float4 cq = rec.svgf_input[q];
            const float wl = expf(-fabsf(lp - luminance(rgb(cq))) / sigma);
            const float w = kernel[dx + 2] * kernel[dy + 2] * wl *
                            geometry_weight(np, xp, unit, rec.aov_normal[q], rec.aov_position[q],
                                            float(pass.step), pass.sigma_z, pass.sigma_n);
            sum += w * rgb(cq);
            variance += w * w * cq.w;
            weights += w;
        }
    // The centre tap's weight is kernel[2]^2 > 0, so weights never vanishes.
    float3 result = sum / weights;
    if (pass.last) {
        rec.svgf_output[p] = make_float4(result * sample_atrous::demodulation(ap), 1.0f);
        return;
    }
    rec.svgf_output[p] = make_float4(result, variance / (weights * weights));
}

LUCENT_RAY_GENERATION(svgf_atrous, sample_svgf::AtrousRecord) {
    sample_svgf::atrous_pixel(rec);
}

struct KeepRecord {
    lucent::BufferView<const float4> aov_normal, aov_position;
    lucent::BufferView<const float4> integrated_colour, integrated_moments;
    lucent::BufferView<float4> history_normal, history_position, history_colour, history_moments;
};
LUCENT_RECORD(KeepRecord, aov_normal, aov_position, integrated_colour, integrated_moments,
              history_normal, history_position, history_colour, history_moments)

LUCENT_RAY_GENERATION(svgf_keep, sample_svgf::KeepRecord) {
    const uint3 i = lucent::launch_index();
    const uint2 p = make_uint2(i.x, i.y);
    rec.history_normal[p] = rec.aov_normal[p];
    rec.history_position[p] = rec.aov_position[p];
    rec.history_colour[p] = rec.integrated_colour[p];
    rec.history_moments[p] = rec.integrated_moments[p];
}

}  // namespace sample_svgf
