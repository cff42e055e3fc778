// The path tracer's BSDFs: evaluation, importance sampling and pdf of Lambert, a GGX metal,
// smooth glass and a GGX-coated Lambert base, in a local frame whose z axis is the shading
// normal turned towards the viewer. Device code (g++, nvcc, NVRTC), also used by host tests.
#pragma once

#include "lucent/device/vector_math.h"
#include "samples/common/fresnel.h"

namespace pathtracer {

constexpr float kPi = 3.14159265358979f;

/// Mirrors scene::MaterialKind; one closest-hit program per kind.
enum MaterialKind : unsigned { kLambert = 0, kMetal = 1, kDielectric = 2, kCoated = 3 };

/// A material as its BSDF sees it. `eta` is the relative index n_transmitted / n_incident
/// (for glass: ior entering, 1 / ior leaving; for the coat: its ior).
struct Bsdf {
    unsigned kind;
    float3 diffuse;   // Lambert and coated base reflectance
    float3 specular;  // the metal's reflectance at normal incidence (Schlick's F0)
    float alpha;      // GGX width, roughness^2 (Burley 2012)
    float eta;
};

struct BsdfSample {
    float3 wi;      // local frame
    float3 weight;  // f cos(theta_i) / pdf; zero when the sample is invalid
    float pdf;      // solid angle; for a delta lobe the probability of choosing it
    bool delta;
};

/// Orthonormal frame around unit n (Duff et al. 2017, "Building an orthonormal basis,
/// revisited").
struct Frame {
    float3 t, b, n;
};
LUCENT_HD inline Frame make_frame(float3 n) {
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    return {make_float3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x),
            make_float3(b, sign + n.y * n.y * a, -n.y), n};
}
LUCENT_HD inline float3 to_local(const Frame& f, float3 v) {
    return make_float3(dot(v, f.t), dot(v, f.b), dot(v, f.n));
}
LUCENT_HD inline float3 to_world(const Frame& f, float3 v) {
    return f.t * v.x + f.b * v.y + f.n * v.z;
}

LUCENT_HD inline float3 sample_cosine_hemisphere(float u1, float u2) {
    const float r = sqrtf(u1), phi = 2.0f * kPi * u2;
    return make_float3(r * cosf(phi), r * sinf(phi), sqrtf(lc_max(0.0f, 1.0f - u1)));
}

/// Unpolarised Fresnel reflectance of a dielectric interface (samples/common/fresnel.h).
using sample_common::fresnel_dielectric;

/// Schlick's approximation (1994) with reflectance f0 at normal incidence.
LUCENT_HD inline float3 fresnel_schlick(float3 f0, float cos_theta) {
    const float m = clampf(1.0f - cos_theta, 0.0f, 1.0f), m2 = m * m;
    return f0 + (make_float3(1.0f) - f0) * (m2 * m2 * m);
}

// ---- GGX (Trowbridge-Reitz) microfacets, Walter et al. 2007 -------------------------------
/// D(h), Walter et al. Eq. 33.
LUCENT_HD inline float ggx_d(float3 h, float alpha) {
    if (h.z <= 0.0f) return 0.0f;
    const float a2 = alpha * alpha, c2 = h.z * h.z;
    const float d = c2 * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
}
/// Smith's Lambda for GGX (Heitz 2014, Eq. 72).
LUCENT_HD inline float ggx_lambda(float3 w, float alpha) {
    const float c2 = w.z * w.z;
    if (c2 <= 0.0f) return 0.0f;
    const float tan2 = lc_max(0.0f, 1.0f - c2) / c2;
    return 0.5f * (sqrtf(1.0f + alpha * alpha * tan2) - 1.0f);
}
LUCENT_HD inline float ggx_g1(float3 w, float alpha) {
    return 1.0f / (1.0f + ggx_lambda(w, alpha));
}
/// Height-correlated masking-shadowing (Heitz 2014, Eq. 99).
LUCENT_HD inline float ggx_g2(float3 wo, float3 wi, float alpha) {
    return 1.0f / (1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}
/// A microfacet normal from the distribution of normals visible from wo (Heitz 2018,
/// "Sampling the GGX distribution of visible normals", listing 1).
LUCENT_HD inline float3 ggx_sample_visible_normal(float3 wo, float alpha, float u1, float u2) {
    const float3 vh = normalize(make_float3(alpha * wo.x, alpha * wo.y, wo.z));
    const float len2 = vh.x * vh.x + vh.y * vh.y;
    const float3 t1 =
        len2 > 0.0f ? make_float3(-vh.y, vh.x, 0.0f) / sqrtf(len2) : make_float3(1.0f, 0.0f, 0.0f);
    const float3 t2 = cross(vh, t1);
    const float r = sqrtf(u1), phi = 2.0f * kPi * u2;
    const float p1 = r * cosf(phi), s = 0.5f * (1.0f + vh.z);
    const float p2 = (1.0f - s) * sqrtf(lc_max(0.0f, 1.0f - p1 * p1)) + s * r * sinf(phi);
    const float3 nh = t1 * p1 + t2 * p2 + vh * sqrtf(lc_max(0.0f, 1.0f - p1 * p1 - p2 * p2));
    return normalize(make_float3(alpha * nh.x, alpha * nh.y, lc_max(1e-6f, nh.z)));
}
/// Solid-angle pdf of wi = reflect(wo, h) with h from the visible normals: D_wo(h) / (4 wo.h)
/// = G1(wo) D(h) / (4 wo.z) (Heitz 2018, Eqs. 3 and 17).
LUCENT_HD inline float ggx_reflection_pdf(float3 wo, float3 wi, float alpha) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    const float3 h = normalize(wo + wi);
    return ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0f * wo.z);
}
/// GGX reflection without Fresnel: D G2 / (4 cos_o cos_i).
LUCENT_HD inline float ggx_reflection(float3 wo, float3 wi, float alpha) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    const float3 h = normalize(wo + wi);
    return ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0f * wo.z * wi.z);
}

/// The coat's Fresnel reflectance (Schlick, f0 from its index), which also chooses its lobe.
LUCENT_HD inline float coat_fresnel(float eta, float cos_theta) {
    const float r = (eta - 1.0f) / (eta + 1.0f);
    return fresnel_schlick(make_float3(r * r), cos_theta).x;
}

LUCENT_HD inline bool is_delta(const Bsdf& b) {
    return b.kind == kDielectric;
}

/// f(wo, wi), without the cosine. Zero for the delta lobes of glass.
LUCENT_HD inline float3 bsdf_eval(const Bsdf& b, float3 wo, float3 wi) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return make_float3(0.0f);
    switch (b.kind) {
        case kLambert:
            return b.diffuse * (1.0f / kPi);
        case kMetal: {
            const float3 h = normalize(wo + wi);
            return fresnel_schlick(b.specular, dot(wi, h)) * ggx_reflection(wo, wi, b.alpha);
        }
        case kCoated: {
            // Coat: GGX reflection with the coat's Fresnel; base: Lambert seen through the
            // coat twice, weighted by what each crossing transmits (Ashikhmin and Shirley
            // 2000 weight the diffuse term of their coated model the same way).
            const float3 h = normalize(wo + wi);
            const float coat = coat_fresnel(b.eta, dot(wi, h)) * ggx_reflection(wo, wi, b.alpha);
            const float through =
                (1.0f - coat_fresnel(b.eta, wo.z)) * (1.0f - coat_fresnel(b.eta, wi.z));
            return make_float3(coat) + b.diffuse * (through / kPi);
        }
        default:
            return make_float3(0.0f);
    }
}

/// The solid-angle pdf with which bsdf_sample returns wi (0 for the delta lobes).
LUCENT_HD inline float bsdf_pdf(const Bsdf& b, float3 wo, float3 wi) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    switch (b.kind) {
        case kLambert:
            return wi.z * (1.0f / kPi);
        case kMetal:
            return ggx_reflection_pdf(wo, wi, b.alpha);
        case kCoated: {
            const float p_coat = coat_fresnel(b.eta, wo.z);
            return p_coat * ggx_reflection_pdf(wo, wi, b.alpha) +
                   (1.0f - p_coat) * wi.z * (1.0f / kPi);
        }
        default:
            return 0.0f;
    }
}

/// Importance-samples wi for wo from three uniform numbers in [0, 1).
LUCENT_HD inline BsdfSample bsdf_sample(const Bsdf& b, float3 wo, float u1, float u2, float u3) {
    BsdfSample s{make_float3(0.0f, 0.0f, 1.0f), make_float3(0.0f), 0.0f, false};
    if (wo.z <= 0.0f) return s;
    if (b.kind == kDielectric) {
        // Smooth glass: reflect with probability F, else refract (the ratio F / F = 1).
        s.delta = true;
        const float f = fresnel_dielectric(wo.z, b.eta);
        if (u3 < f) {
            s.wi = make_float3(-wo.x, -wo.y, wo.z);
            s.weight = make_float3(1.0f);
            s.pdf = f;
        } else {
            refract(s.wi, -wo, make_float3(0.0f, 0.0f, 1.0f), 1.0f / b.eta);
            // Radiance is compressed into the smaller solid angle on the denser side
            // (Veach 1997, §5.2): 1 / eta^2.
            s.weight = make_float3(1.0f / (b.eta * b.eta));
            s.pdf = 1.0f - f;
        }
        return s;
    }
    if (b.kind == kLambert) {
        s.wi = sample_cosine_hemisphere(u1, u2);
    } else if (b.kind == kMetal || u3 < coat_fresnel(b.eta, wo.z)) {
        const float3 h = ggx_sample_visible_normal(wo, b.alpha, u1, u2);
        s.wi = reflect(-wo, h);
    } else {
        s.wi = sample_cosine_hemisphere(u1, u2);
    }
    s.pdf = bsdf_pdf(b, wo, s.wi);
    if (s.pdf > 0.0f) s.weight = bsdf_eval(b, wo, s.wi) * (s.wi.z / s.pdf);
    return s;
}

}  // namespace pathtracer
