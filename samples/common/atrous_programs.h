// The edge-avoiding à-trous wavelet filter (Dammertz, Sewtz, Hanika and Lensch 2010,
// "Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination Filtering"): each
// pass convolves with the 5x5 B3-spline kernel h = (1, 4, 6, 4, 1) / 16 (separable, the
// paper's Fig. 2) whose taps are 2^i pixels apart (the "holes", §3.1), and multiplies every
// tap by edge-stopping weights on colour, normal and position (§3.2, Eq. 5-7):
//   w(p, q) = w_rt w_n w_x,  w_rt = exp(-|c_p - c_q|^2 / sigma_rt),
//   w_n = exp(-|n_p - n_q|^2 / (2^i)^2 / sigma_n),  w_x = exp(-d_x(p, q)^2 / sigma_x),
// in the form of the paper's GLSL shader (the sigmas there are the phi parameters, not
// squared; the normal distance is divided by the step width squared). sigma_rt halves with
// each pass (§3.2: 2^-i sigma_rt), as the filtered colour grows smoother.
//
// Two departures, both for a Monte Carlo path tracer rather than the paper's one-bounce
// rasteriser: the colour is filtered as illumination, divided by the G-buffer's albedo in
// the first pass and multiplied back in the last (texture detail is then not blurred; Schied
// et al. 2017 §4.1 do the same), and sigma_rt is given relative to the image's mean
// illumination, so one value suits any exposure. The position distance d_x is measured from
// p to q's tangent plane, in units of p's pixel footprint (its width at p's depth), so one
// sigma_x suits any scene scale (the Cornell box is in millimetres) and an oblique plane is
// not mistaken for an edge.
//
// For speed (the filter is bound by the bytes its 25 taps load): a first launch, `prepare`,
// writes each pixel's filter input (the demodulated colour) and its guide, q's tangent plane
// as one float4 (normal, n . x; a zero normal where no surface was hit), so a tap loads 32
// bytes instead of the G-buffer's 64. In the same launch the first pixel of each 16x16 block
// sums the illumination of every second pixel of every second row of its block, so the
// host reads one float2 per block and adds them in a fixed order (the same mean on every
// backend and device list) instead of reading the whole image. The three weights of a tap
// share one exponential.
#pragma once

#include "lucent/device.h"
#include "samples/common/camera.h"

namespace sample_atrous {

/// The module of the denoiser's programs (lucent/device/module.h).
LUCENT_MODULE(sample_atrous)

/// The blocks of the mean illumination's sums, and the stride of their samples.
constexpr unsigned kMeanBlock = 16, kMeanStride = 2;

/// One pass's parameters: a 1-element buffer uploaded before each launch (new contents
/// recompile nothing; a variable would).
struct AtrousPass {
    unsigned step;        // 2^i: the distance between the kernel's taps, in pixels
    unsigned last;        // 1: multiply the result back by the albedo
    unsigned demodulate;  // 0: filter the colour itself (the paper's form)
    float sigma_colour;   // already scaled: sigma_rt x mean illumination^2 x 2^-i
    float sigma_normal;
    float sigma_position;
    float footprint;      // a pixel's width at depth 1: 2 |V| / height
};

struct PrepareRecord {
    lucent::BufferView<const AtrousPass> atrous_pass;  // demodulate is read
    lucent::BufferView<const float4> atrous_colour;    // the sample's image
    lucent::BufferView<float4> atrous_output;          // the filter's input
    lucent::BufferView<float4> atrous_guide;           // normal, n . x
    lucent::BufferView<float2> atrous_sums;  // per 16x16 block (row-major): sum, pixels
    lucent::BufferView<const float4> aov_albedo;       // rgb; a = coverage
    lucent::BufferView<const float4> aov_normal;       // xyz; w = instance
    lucent::BufferView<const float4> aov_position;     // xyz; w = depth
};
LUCENT_RECORD(PrepareRecord, atrous_pass, atrous_colour, atrous_output, atrous_guide,
              atrous_sums, aov_albedo, aov_normal, aov_position)

struct PassRecord {
    lucent::BufferView<const AtrousPass> atrous_pass;  // one element
    lucent::BufferView<const float4> atrous_input;
    lucent::BufferView<float4> atrous_output;
    lucent::BufferView<const float4> atrous_guide;
    lucent::BufferView<const float4> aov_albedo;    // the last pass multiplies it back
    lucent::BufferView<const float4> aov_position;  // p's own position and depth
};
LUCENT_RECORD(PassRecord, atrous_pass, atrous_input, atrous_output, atrous_guide, aov_albedo,
              aov_position)

/// The albedo a pixel's colour is divided by: channels below 1e-3 (black, or an emitter
/// whose Kd is 0) are left as they are, so the division never blows up.
LUCENT_HD inline float3 demodulation(float4 albedo) {
    return make_float3(albedo.x >= 1e-3f ? albedo.x : 1.0f, albedo.y >= 1e-3f ? albedo.y : 1.0f,
                       albedo.z >= 1e-3f ? albedo.z : 1.0f);
}

/// The demodulated colour of a pixel as the filter takes it.
LUCENT_HD inline float3 filter_input(float4 colour, float4 albedo, bool demodulate) {
    const float3 v = make_float3(colour.x, colour.y, colour.z);
    return demodulate ? v / demodulation(albedo) : v;
}

/// Prepares pixel p: its filter input and tangent plane; the first pixel of a block also
/// sums the block's samples of the mean illumination (covered pixels' mean channel, finite).
LUCENT_HD inline void prepare_pixel(const PrepareRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const bool demodulate = rec.atrous_pass[0u].demodulate != 0;
    const float4 a = rec.aov_albedo[p];
    rec.atrous_output[p] = make_float4(filter_input(rec.atrous_colour[p], a, demodulate), 1.0f);
    if (a.w > 0.5f) {
        const float4 nn = rec.aov_normal[p], x4 = rec.aov_position[p];
        const float3 normal = make_float3(nn.x, nn.y, nn.z);
        rec.atrous_guide[p] = make_float4(normal, dot(normal, make_float3(x4.x, x4.y, x4.z)));
    } else {
        rec.atrous_guide[p] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    }
    if (p.x % kMeanBlock != 0 || p.y % kMeanBlock != 0) return;
    float sum = 0.0f, covered = 0.0f;
    for (unsigned y = p.y; y < p.y + kMeanBlock && y < n.y; y += kMeanStride)
        for (unsigned x = p.x; x < p.x + kMeanBlock && x < n.x; x += kMeanStride) {
            const uint2 q = make_uint2(x, y);
            const float4 aq = rec.aov_albedo[q];
            if (aq.w <= 0.5f) continue;
            const float3 v = filter_input(rec.atrous_colour[q], aq, demodulate);
            const float mean = (v.x + v.y + v.z) / 3.0f;
            if (fabsf(mean) <= 3.402823466e38f) sum += mean;  // finite: not NaN or inf
            covered += 1.0f;
        }
    const unsigned blocks_x = (n.x + kMeanBlock - 1) / kMeanBlock;
    rec.atrous_sums[p.y / kMeanBlock * blocks_x + p.x / kMeanBlock] = make_float2(sum, covered);
}

/// One pass at pixel p: the weighted mean of the 25 taps (Dammertz et al. 2010, Eq. 4 and 5).
LUCENT_HD inline void atrous_pixel(const PassRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const AtrousPass pass = rec.atrous_pass[0u];
    const float kernel[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
    const float4 cp4 = rec.atrous_input[p], gp = rec.atrous_guide[p];
    const float3 cp = make_float3(cp4.x, cp4.y, cp4.z), np = make_float3(gp.x, gp.y, gp.z);
    const bool covered = gp.x != 0.0f || gp.y != 0.0f || gp.z != 0.0f;
    const float4 xp4 = rec.aov_position[p];
    const float3 xp = make_float3(xp4.x, xp4.y, xp4.z);
    // The exponents' divisors, inverted once (the normal's is divided by the step squared).
    const float step = float(pass.step);
    const float colour_scale = 1.0f / lc_max(pass.sigma_colour, 1e-30f);
    const float normal_scale = 1.0f / (step * step * pass.sigma_normal);
    // The plane distance's unit at p: the width of its pixel at its depth.
    const float unit = lc_max(pass.footprint * xp4.w, 1e-20f);
    const float position_scale = 1.0f / (unit * unit * pass.sigma_position);
    float3 sum = make_float3(0.0f);
    float weights = 0.0f;
    for (int dy = -2; dy <= 2; ++dy) {
        const int qy = int(p.y) + dy * int(pass.step);
        if (qy < 0 || qy >= int(n.y)) continue;
        for (int dx = -2; dx <= 2; ++dx) {
            const int qx = int(p.x) + dx * int(pass.step);
            if (qx < 0 || qx >= int(n.x)) continue;
            const uint2 q = make_uint2(unsigned(qx), unsigned(qy));
            const float4 gq = rec.atrous_guide[q];
            const float3 nq = make_float3(gq.x, gq.y, gq.z);
            const bool q_covered = gq.x != 0.0f || gq.y != 0.0f || gq.z != 0.0f;
            if (q_covered != covered) continue;  // a surface never takes the background
            const float4 cq4 = rec.atrous_input[q];
            const float3 cq = make_float3(cq4.x, cq4.y, cq4.z);
            const float3 dc = cp - cq;
            // Eq. 5-7's three factors as one exponential of the summed exponents.
            float exponent = dot(dc, dc) * colour_scale;
            if (covered) {
                const float3 dn = np - nq;
                const float plane = dot(nq, xp) - gq.w;  // p's distance to q's tangent plane
                exponent += dot(dn, dn) * normal_scale + plane * plane * position_scale;
            }
            const float w = kernel[dx + 2] * kernel[dy + 2] * expf(-exponent);
            sum += w * cq;
            weights += w;
        }
    }
    // The centre tap's weight is kernel[2]^2 > 0, so weights never vanishes.
    float3 result = sum / weights;
    if (pass.last && pass.demodulate) result = result * demodulation(rec.aov_albedo[p]);
    rec.atrous_output[p] = make_float4(result, 1.0f);
}

LUCENT_RAY_GENERATION(atrous_prepare, sample_atrous::PrepareRecord) {
    sample_atrous::prepare_pixel(rec);
}

LUCENT_RAY_GENERATION(atrous, sample_atrous::PassRecord) {
    sample_atrous::atrous_pixel(rec);
}

}  // namespace sample_atrous
