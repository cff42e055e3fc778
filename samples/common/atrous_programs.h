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
// q to p's tangent plane, in units of p's pixel footprint (its width at p's depth), so one
// sigma_x suits any scene scale (the Cornell box is in millimetres) and an oblique plane is
// not mistaken for an edge.
#pragma once

#include "lucent/device.h"
#include "samples/common/camera.h"

namespace sample_atrous {

/// The module of the denoiser's programs (lucent/device/module.h).
LUCENT_MODULE(sample_atrous)

/// One pass's parameters: a 1-element buffer uploaded before each launch (new contents
/// recompile nothing; a variable would).
struct AtrousPass {
    unsigned step;        // 2^i: the distance between the kernel's taps, in pixels
    unsigned first;       // 1: the input is colour, divide it by the albedo
    unsigned last;        // 1: multiply the result back by the albedo
    unsigned demodulate;  // 0: filter the colour itself (the paper's form)
    float sigma_colour;   // already scaled: sigma_rt x mean illumination^2 x 2^-i
    float sigma_normal;
    float sigma_position;
    float footprint;      // a pixel's width at depth 1: 2 |V| / height
};

struct PassRecord {
    lucent::BufferView<const AtrousPass> atrous_pass;  // one element
    lucent::BufferView<const float4> atrous_input;
    lucent::BufferView<float4> atrous_output;
    lucent::BufferView<const float4> aov_albedo;    // rgb; a = coverage
    lucent::BufferView<const float4> aov_normal;    // xyz; w = instance
    lucent::BufferView<const float4> aov_position;  // xyz; w = depth
};
LUCENT_RECORD(PassRecord, atrous_pass, atrous_input, atrous_output, aov_albedo, aov_normal,
              aov_position)

/// The albedo a pixel's colour is divided by: channels below 1e-3 (black, or an emitter
/// whose Kd is 0) are left as they are, so the division never blows up.
LUCENT_HD inline float3 demodulation(float4 albedo) {
    return make_float3(albedo.x >= 1e-3f ? albedo.x : 1.0f, albedo.y >= 1e-3f ? albedo.y : 1.0f,
                       albedo.z >= 1e-3f ? albedo.z : 1.0f);
}

/// The filter's input at q as the pass filters it: illumination in the first pass when
/// demodulating, else the previous pass's result.
LUCENT_HD inline float3 pass_input(const PassRecord& rec, const AtrousPass& pass, uint2 q) {
    const float4 c = rec.atrous_input[q];
    float3 v = make_float3(c.x, c.y, c.z);
    if (pass.first && pass.demodulate) v = v / demodulation(rec.aov_albedo[q]);
    return v;
}

/// One pass at pixel p: the weighted mean of the 25 taps (Dammertz et al. 2010, Eq. 4 and 5).
LUCENT_HD inline void atrous_pixel(const PassRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 p = make_uint2(i.x, i.y);
    const AtrousPass pass = rec.atrous_pass[0u];
    const float kernel[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
    const float3 cp = pass_input(rec, pass, p);
    const float4 ap = rec.aov_albedo[p], np4 = rec.aov_normal[p], xp4 = rec.aov_position[p];
    const float3 np = make_float3(np4.x, np4.y, np4.z), xp = make_float3(xp4.x, xp4.y, xp4.z);
    const bool covered = ap.w > 0.5f;
    const float step = float(pass.step);  // the normal distance is divided by its square
    // The plane distance's unit at p: the width of its pixel at its depth.
    const float unit = lc_max(pass.footprint * xp4.w, 1e-20f);
    float3 sum = make_float3(0.0f);
    float weights = 0.0f;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            const int qx = int(p.x) + dx * int(pass.step), qy = int(p.y) + dy * int(pass.step);
            if (qx < 0 || qy < 0 || qx >= int(n.x) || qy >= int(n.y)) continue;
            const uint2 q = make_uint2(unsigned(qx), unsigned(qy));
            const float4 aq = rec.aov_albedo[q];
            if ((aq.w > 0.5f) != covered) continue;  // a surface never takes the background
            const float3 cq = pass_input(rec, pass, q);
            const float3 dc = cp - cq;
            float w = kernel[dx + 2] * kernel[dy + 2] *
                      expf(-dot(dc, dc) / lc_max(pass.sigma_colour, 1e-30f));
            if (covered) {
                const float4 nq4 = rec.aov_normal[q], xq4 = rec.aov_position[q];
                const float3 dn = np - make_float3(nq4.x, nq4.y, nq4.z);
                w *= expf(-dot(dn, dn) / (step * step) / pass.sigma_normal);
                const float dx_plane = dot(np, make_float3(xq4.x, xq4.y, xq4.z) - xp) / unit;
                w *= expf(-dx_plane * dx_plane / pass.sigma_position);
            }
            sum += w * cq;
            weights += w;
        }
    }
    // The centre tap's weight is kernel[2]^2 > 0, so weights never vanishes.
    float3 result = sum / weights;
    if (pass.last && pass.demodulate) result = result * demodulation(ap);
    rec.atrous_output[p] = make_float4(result, 1.0f);
}

LUCENT_RAY_GENERATION(atrous, sample_atrous::PassRecord) {
    sample_atrous::atrous_pixel(rec);
}

}  // namespace sample_atrous
