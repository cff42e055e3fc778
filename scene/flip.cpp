// FLIP's two pipelines (the paper's Fig. 2): colour (CSF filtering in the opponent space
// YyCxCz, Hunt-adjusted L*a*b*, the HyAB distance, redistributed to [0, 1]) and features
// (edges and points of the achromatic channel), combined as dE_c^(1 - dE_f) (Eq. 9).
#include "scene/flip.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "lucent/error.h"

namespace lucent::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;
// The paper's exponents and redistribution (Sec. 4): q_c, q_f, p_c, p_t.
constexpr float kQc = 0.7f, kQf = 0.5f, kPc = 0.4f, kPt = 0.95f;
// The D65 white point in XYZ.
constexpr float kWhite[3] = {0.950428545f, 1.0f, 1.088900371f};

/// One channel of an image, row-major.
struct Plane {
    unsigned width = 0, height = 0;
    std::vector<float> v;
    float& at(unsigned x, unsigned y) { return v[size_t(y) * width + x]; }
    float at(unsigned x, unsigned y) const { return v[size_t(y) * width + x]; }
};

struct Planes {
    Plane c[3];
};

float3 linear_rgb_to_xyz(float3 c) {
    return make_float3(
        (10135552.0f / 24577794.0f) * c.x + (8788810.0f / 24577794.0f) * c.y + (4435075.0f / 24577794.0f) * c.z,
        (2613072.0f / 12288897.0f) * c.x + (8788810.0f / 12288897.0f) * c.y + (887015.0f / 12288897.0f) * c.z,
        (1425312.0f / 73733382.0f) * c.x + (8788810.0f / 73733382.0f) * c.y + (70074185.0f / 73733382.0f) * c.z);
}

float3 xyz_to_linear_rgb(float3 c) {
    return make_float3(3.241003275f * c.x - 1.537398934f * c.y - 0.498615861f * c.z,
                       -0.969224334f * c.x + 1.875930071f * c.y + 0.041554224f * c.z,
                       0.055639423f * c.x - 0.204011202f * c.y + 1.057148933f * c.z);
}

/// The opponent space of the spatial filtering: achromatic Yy and chromatic Cx, Cz.
float3 xyz_to_ycxcz(float3 c) {
    const float x = c.x / kWhite[0], y = c.y / kWhite[1], z = c.z / kWhite[2];
    return make_float3(116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z));
}

float3 ycxcz_to_xyz(float3 c) {
    const float y = (c.x + 16.0f) / 116.0f;
    return make_float3((y + c.y / 500.0f) * kWhite[0], y * kWhite[1], (y - c.z / 200.0f) * kWhite[2]);
}

/// CIE L*a*b* with the a*, b* scaled by 0.01 L* (the Hunt effect: colour differences look
/// smaller in the dark).
float3 hunt_adjusted_lab(float3 xyz) {
    constexpr float delta = 6.0f / 29.0f;
    auto f = [&](float t) {
        return t > delta * delta * delta ? std::cbrt(t) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
    };
    const float fx = f(xyz.x / kWhite[0]), fy = f(xyz.y / kWhite[1]), fz = f(xyz.z / kWhite[2]);
    const float L = 116.0f * fy - 16.0f;
    return make_float3(L, 0.01f * L * 500.0f * (fx - fy), 0.01f * L * 200.0f * (fy - fz));
}

/// HyAB (Abasi et al. 2020): the lightness difference plus the Euclidean chroma difference.
float hyab(float3 a, float3 b) {
    const float3 d = a - b;
    return std::fabs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

/// Correlates rows, then columns, with 1D kernels (centre at index r), borders replicated.
Plane separable(const Plane& in, const std::vector<float>& along_x, const std::vector<float>& along_y) {
    const int rx = int(along_x.size() / 2), ry = int(along_y.size() / 2);
    const int w = int(in.width), h = int(in.height);
    Plane rows{in.width, in.height, std::vector<float>(in.v.size())};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float sum = 0;
            for (int k = -rx; k <= rx; ++k) sum += along_x[k + rx] * in.at(std::clamp(x + k, 0, w - 1), y);
            rows.at(x, y) = sum;
        }
    Plane out{in.width, in.height, std::vector<float>(in.v.size())};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float sum = 0;
            for (int k = -ry; k <= ry; ++k) sum += along_y[k + ry] * rows.at(x, std::clamp(y + k, 0, h - 1));
            out.at(x, y) = sum;
        }
    return out;
}

/// A contrast sensitivity function as the sum of Gaussians a sqrt(pi / b) exp(-pi^2 d^2 / b)
/// (d in degrees; Sec. 4.1, after Johnson and Fairchild), normalised to sum 1 over the
/// kernel. Each term is separable, so the channel is filtered term by term.
struct CsfTerm {
    float a, b;
};

Plane csf_filtered(const Plane& in, const std::vector<CsfTerm>& terms, int radius, double ppd) {
    std::vector<std::vector<float>> kernels;
    std::vector<double> weights;
    double total = 0;
    for (const CsfTerm& t : terms) {
        std::vector<float> k(2 * radius + 1);
        double sum = 0;
        for (int i = -radius; i <= radius; ++i) {
            const double d = i / ppd;
            k[i + radius] = float(std::exp(-kPi * kPi * d * d / t.b));
            sum += k[i + radius];
        }
        const double weight = t.a * std::sqrt(kPi / t.b);
        total += weight * sum * sum;  // the 2D kernel's sum
        kernels.push_back(std::move(k));
        weights.push_back(weight);
    }
    Plane out{in.width, in.height, std::vector<float>(in.v.size(), 0.0f)};
    for (size_t t = 0; t < terms.size(); ++t) {
        const Plane filtered = separable(in, kernels[t], kernels[t]);
        const float scale = float(weights[t] / total);
        for (size_t i = 0; i < out.v.size(); ++i) out.v[i] += scale * filtered.v[i];
    }
    return out;
}

/// The colour pipeline's image: YyCxCz filtered by each channel's CSF, back to linear RGB
/// clamped to the unit cube, then Hunt-adjusted L*a*b*.
std::vector<float3> filtered_lab(const Planes& opponent, double ppd) {
    // The CSFs' parameters (Sec. 4.1): achromatic, red-green, blue-yellow.
    const std::vector<CsfTerm> achromatic{{1.0f, 0.0047f}}, red_green{{1.0f, 0.0053f}},
        blue_yellow{{34.1f, 0.04f}, {13.5f, 0.025f}};
    // The widest Gaussian (b = 0.04) out to three standard deviations.
    const int radius = int(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * kPi * kPi)) * ppd));
    const Plane y = csf_filtered(opponent.c[0], achromatic, radius, ppd);
    const Plane cx = csf_filtered(opponent.c[1], red_green, radius, ppd);
    const Plane cz = csf_filtered(opponent.c[2], blue_yellow, radius, ppd);
    std::vector<float3> lab(y.v.size());
    for (size_t i = 0; i < lab.size(); ++i) {
        float3 rgb = xyz_to_linear_rgb(ycxcz_to_xyz(make_float3(y.v[i], cx.v[i], cz.v[i])));
        rgb = make_float3(std::clamp(rgb.x, 0.0f, 1.0f), std::clamp(rgb.y, 0.0f, 1.0f),
                          std::clamp(rgb.z, 0.0f, 1.0f));
        lab[i] = hunt_adjusted_lab(linear_rgb_to_xyz(rgb));
    }
    return lab;
}

/// Edge (first derivative) or point (second derivative) detector of Gaussian with the
/// width of the eye's edge detection (Sec. 4.2: 0.082 degrees peak to trough), along x; its
/// positive weights sum to 1 and its negative ones to -1.
struct FeatureKernels {
    std::vector<float> edge, point, gauss;
};

FeatureKernels feature_kernels(double ppd) {
    const double sd = 0.5 * 0.082 * ppd;
    const int radius = int(std::ceil(3.0 * sd));
    FeatureKernels k;
    std::vector<double> g, e, p;
    double gsum = 0;
    for (int i = -radius; i <= radius; ++i) {
        const double gi = std::exp(-double(i) * i / (2.0 * sd * sd));
        g.push_back(gi);
        gsum += gi;
        e.push_back(-i * gi);
        p.push_back((double(i) * i / (sd * sd) - 1.0) * gi);
    }
    // The 2D kernel is derivative(x) gauss(y): normalising its signs splits into the two.
    auto signs_normalised = [](const std::vector<double>& h) {
        double pos = 0, neg = 0;
        for (double v : h) (v > 0 ? pos : neg) += v;
        std::vector<float> out;
        for (double v : h) out.push_back(float(v > 0 ? v / pos : v < 0 ? v / -neg : 0.0));
        return out;
    };
    k.edge = signs_normalised(e);
    k.point = signs_normalised(p);
    for (double v : g) k.gauss.push_back(float(v / gsum));
    return k;
}

/// |gradient| of edges and points of the normalised achromatic channel, per pixel.
void features(const Plane& y_normalised, const FeatureKernels& k, std::vector<float>& edges,
              std::vector<float>& points) {
    const Plane ex = separable(y_normalised, k.edge, k.gauss), ey = separable(y_normalised, k.gauss, k.edge);
    const Plane px = separable(y_normalised, k.point, k.gauss), py = separable(y_normalised, k.gauss, k.point);
    edges.resize(ex.v.size());
    points.resize(ex.v.size());
    for (size_t i = 0; i < ex.v.size(); ++i) {
        edges[i] = std::hypot(ex.v[i], ey.v[i]);
        points[i] = std::hypot(px.v[i], py.v[i]);
    }
}

Planes opponent_planes(const Image& image) {
    Planes p;
    for (Plane& c : p.c) c = Plane{image.width, image.height, std::vector<float>(image.pixels.size())};
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const float3 rgb = image.pixels[i];
        // As displayed: LDR-FLIP compares sRGB images in [0, 1], i.e. linear RGB clamped.
        const float3 clamped = make_float3(std::clamp(rgb.x, 0.0f, 1.0f), std::clamp(rgb.y, 0.0f, 1.0f),
                                           std::clamp(rgb.z, 0.0f, 1.0f));
        const float3 o = xyz_to_ycxcz(linear_rgb_to_xyz(clamped));
        p.c[0].v[i] = o.x;
        p.c[1].v[i] = o.y;
        p.c[2].v[i] = o.z;
    }
    return p;
}

}  // namespace

std::vector<float> flip_error_map(const Image& reference, const Image& test, double pixels_per_degree) {
    if (reference.width != test.width || reference.height != test.height)
        throw Error("FLIP: the images differ in size (" + std::to_string(reference.width) + "x" +
                    std::to_string(reference.height) + " and " + std::to_string(test.width) + "x" +
                    std::to_string(test.height) + "); compare images of one size");
    if (!(pixels_per_degree >= 1.0 && pixels_per_degree <= 1000.0))
        throw Error("FLIP: pixels per degree " + std::to_string(pixels_per_degree) +
                    " is outside [1, 1000]");
    const Planes ref = opponent_planes(reference), tst = opponent_planes(test);

    // Colour: HyAB^q_c between the filtered images, redistributed so that p_c of the largest
    // difference (green against blue) maps to p_t (Eq. 4).
    const std::vector<float3> ref_lab = filtered_lab(ref, pixels_per_degree);
    const std::vector<float3> tst_lab = filtered_lab(tst, pixels_per_degree);
    const float cmax = std::pow(hyab(hunt_adjusted_lab(linear_rgb_to_xyz(make_float3(0, 1, 0))),
                                     hunt_adjusted_lab(linear_rgb_to_xyz(make_float3(0, 0, 1)))),
                                kQc);
    const float pccmax = kPc * cmax;

    // Features of the achromatic channel, normalised to [0, 1] (Sec. 4.2).
    const FeatureKernels kernels = feature_kernels(pixels_per_degree);
    auto normalised_y = [](const Planes& p) {
        Plane y = p.c[0];
        for (float& v : y.v) v = (v + 16.0f) / 116.0f;
        return y;
    };
    std::vector<float> ref_edges, ref_points, tst_edges, tst_points;
    features(normalised_y(ref), kernels, ref_edges, ref_points);
    features(normalised_y(tst), kernels, tst_edges, tst_points);

    std::vector<float> error(ref_lab.size());
    for (size_t i = 0; i < error.size(); ++i) {
        const float color = std::pow(hyab(ref_lab[i], tst_lab[i]), kQc);
        const float dec = color < pccmax ? (kPt / pccmax) * color
                                         : kPt + (color - pccmax) / (cmax - pccmax) * (1.0f - kPt);
        const float feature = std::max(std::fabs(ref_edges[i] - tst_edges[i]),
                                       std::fabs(ref_points[i] - tst_points[i]));
        const float def = std::pow(feature / std::sqrt(2.0f), kQf);
        error[i] = std::pow(dec, 1.0f - def);
    }
    return error;
}

}  // namespace lucent::scene
