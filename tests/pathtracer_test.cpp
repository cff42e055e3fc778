// The path tracer (OptiX paper §6.2): furnace tests with closed-form answers, chi-square tests
// of every BSDF's sampling against its pdf (as pbrt and Mitsuba test theirs), Fresnel
// probabilities of glass, 1/sqrt(spp) convergence, and NEE + MIS against BSDF sampling only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <vector>

#include "samples/sample.h"
#include "samples/pathtracer/pathtracer_bsdf.h"
#include "tests/test_support.h"

namespace {

namespace fs = std::filesystem;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using pathtracer::Bsdf;

RenderResult render(const std::string& scene, unsigned size, unsigned spp,
                    const std::map<std::string, std::string>& sets = {}) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = scene;
    settings.spp = spp;
    settings.sets = sets;
    return lucent::samples::find_sample("pathtracer").render(settings);
}

float3 mean_of(const RenderResult& r, unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
    double s[3] = {0, 0, 0};
    for (unsigned y = y0; y < y1; ++y)
        for (unsigned x = x0; x < x1; ++x) {
            const float3 p = r.image.pixels[size_t(y) * r.image.width + x];
            s[0] += p.x, s[1] += p.y, s[2] += p.z;
        }
    const double n = double(x1 - x0) * (y1 - y0);
    return make_float3(float(s[0] / n), float(s[1] / n), float(s[2] / n));
}

// ---- furnace scenes: an icosphere written as a JSON scene --------------------------------------
/// A unit icosphere subdivided `levels` times, wound outwards (or inwards when `inward`).
void icosphere(std::vector<float3>& p, std::vector<uint3>& t, int levels, bool inward) {
    const float g = (1.0f + std::sqrt(5.0f)) / 2.0f;
    p = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
    t = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<unsigned, unsigned>, unsigned> mid;
        auto middle = [&](unsigned a, unsigned b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            p.push_back(0.5f * (p[a] + p[b]));
            return mid[key] = unsigned(p.size() - 1);
        };
        std::vector<uint3> next;
        for (const uint3& f : t) {
            const unsigned a = middle(f.x, f.y), b = middle(f.y, f.z), c = middle(f.z, f.x);
            next.insert(next.end(), {{f.x, a, c}, {f.y, b, a}, {f.z, c, b}, {a, b, c}});
        }
        t = next;
    }
    for (float3& v : p) v = normalize(v);
    if (inward)
        for (uint3& f : t) std::swap(f.y, f.z);
}

class Furnace : public ::testing::Test {
  protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / ("lucent-pt-test-" + std::to_string(::getpid()));
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    /// A sphere of radius 1 at the origin with `material` (JSON), seen from `eye`.
    std::string sphere_scene(const std::string& material, float3 eye, bool inward) {
        std::vector<float3> p;
        std::vector<uint3> t;
        icosphere(p, t, 3, inward);
        std::ostringstream json;
        json << R"({"camera": {"eye": [)" << eye.x << "," << eye.y << "," << eye.z
             << R"(], "look": [0, 0, 0.001], "fov": 40}, "materials": [)" << material
             << R"(], "meshes": [{"material": "m", "positions": [)";
        for (size_t i = 0; i < p.size(); ++i)
            json << (i ? "," : "") << "[" << p[i].x << "," << p[i].y << "," << p[i].z << "]";
        json << R"(], "triangles": [)";
        for (size_t i = 0; i < t.size(); ++i)
            json << (i ? "," : "") << "[" << t[i].x << "," << t[i].y << "," << t[i].z << "]";
        json << "]}]}";
        const fs::path path = dir / "furnace.json";
        std::ofstream(path) << json.str();
        return path.string();
    }
    fs::path dir;
};

TEST_F(Furnace, LambertSphereReflectsItsAlbedoOfAUniformEnvironment) {
    // A convex Lambert sphere of albedo a under uniform radiance L: every reflected ray
    // escapes, so L_o = a L exactly; around it the environment, L.
    const std::string scene =
        sphere_scene(R"({"name": "m", "diffuse": [0.5, 0.3, 0.8]})", make_float3(0, 0, 4), false);
    const RenderResult r = render(scene, 32, 16, {{"environment", "1"}});
    EXPECT_EQ(r.report.exception_count(), 0u);
    const float3 sphere = mean_of(r, 12, 12, 20, 20);
    EXPECT_NEAR(sphere.x, 0.5f, 1e-3f);
    EXPECT_NEAR(sphere.y, 0.3f, 1e-3f);
    EXPECT_NEAR(sphere.z, 0.8f, 1e-3f);
    const float3 corner = mean_of(r, 0, 0, 3, 3);
    EXPECT_FLOAT_EQ(corner.x + corner.y + corner.z, 3.0f);
}

TEST_F(Furnace, GlassSphereNeitherGainsNorLosesEnergy) {
    // Smooth glass reflects or transmits all it receives: the sphere vanishes into the
    // furnace (every path's weight, 1 / eta^2 in and eta^2 out, averages to 1).
    const std::string scene = sphere_scene(R"({"name": "m", "type": "dielectric", "ior": 1.5})",
                                           make_float3(0, 0, 4), false);
    const RenderResult r = render(scene, 32, 64, {{"environment", "1"}, {"max_depth", "64"}});
    const float3 sphere = mean_of(r, 12, 12, 20, 20);
    EXPECT_NEAR(sphere.x, 1.0f, 0.02f);
    EXPECT_NEAR(sphere.z, 1.0f, 0.02f);
}

TEST_F(Furnace, InsideAnEmittingLambertSphereRadianceIsEmissionOverOneMinusAlbedo) {
    // pbrt's closed furnace: inside a sphere of emission E and albedo a every path adds
    // E a^k, so L = E / (1 - a): all bounces, Russian roulette included.
    const std::string scene =
        sphere_scene(R"({"name": "m", "diffuse": [0.5, 0.5, 0.5], "emission": [0.5, 0.5, 0.5]})",
                     make_float3(0, 0, 0.5f), true);
    const RenderResult r = render(scene, 16, 64, {{"max_depth", "200"}});
    EXPECT_EQ(r.report.exception_count(), 0u);
    const float3 all = mean_of(r, 0, 0, 16, 16);
    EXPECT_NEAR(all.x, 1.0f, 0.02f);
    // Two path segments (before Russian roulette starts) stop at exactly E (1 + a).
    const RenderResult short_paths = render(scene, 16, 4, {{"max_depth", "2"}});
    EXPECT_NEAR(mean_of(short_paths, 0, 0, 16, 16).x, 0.75f, 1e-3f);
}

TEST_F(Furnace, JsonAreaLightWithoutASurfaceIsFoundByBothStrategies) {
    // A JSON area light has no triangles: the sample gives it some, or BSDF-sampled rays
    // would never find it and MIS would lose its share of the light.
    const fs::path path = dir / "lamp.json";
    std::ofstream(path) << R"({"camera": {"eye": [0, 0.6, 2.5], "look": [0, 0.2, 0], "fov": 50},
      "materials": [{"name": "grey", "diffuse": [0.5, 0.5, 0.5]}],
      "meshes": [{"positions": [[-1,0,-1], [1,0,-1], [1,0,1], [-1,0,1]],
                  "triangles": [[0,2,1], [0,3,2]], "material": "grey"}],
      "lights": [{"type": "area", "corner": [-0.5, 1, -0.5], "edge1": [1, 0, 0],
                  "edge2": [0, 0, 1], "emission": [2, 2, 2]}]})";
    const RenderResult mis = render(path.string(), 16, 64, {{"nee", "1"}});
    const RenderResult bsdf = render(path.string(), 16, 256, {{"nee", "0"}});
    const float a = mean_of(mis, 0, 0, 16, 16).x, b = mean_of(bsdf, 0, 0, 16, 16).x;
    EXPECT_GT(b, 0.05f) << "BSDF sampling alone finds the light";
    EXPECT_NEAR(a / b, 1.0f, 0.03f);
}

// ---- chi-square tests of the BSDF sampling ------------------------------------------------
/// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes §6.2): the chi-square
/// distribution's tail, Q(dof / 2, chi2 / 2).
double gamma_q(double a, double x) {
    if (x <= 0) return 1.0;
    const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1) {  // series for P
        double sum = 1.0 / a, term = sum;
        for (int n = 1; n < 1000; ++n) {
            term *= x / (a + n);
            sum += term;
            if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
        }
        return 1.0 - sum * std::exp(log_prefix);
    }
    double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;  // Lentz's continued fraction for Q
    for (int i = 1; i < 1000; ++i) {
        const double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::fabs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (std::fabs(c) < 1e-300) c = 1e-300;
        d = 1 / d;
        const double delta = d * c;
        h *= delta;
        if (std::fabs(delta - 1) < 1e-15) break;
    }
    return std::exp(log_prefix) * h;
}

TEST(ChiSquare, IncompleteGammaMatchesKnownTails) {
    EXPECT_NEAR(gamma_q(1.0, 2.0), std::exp(-2.0), 1e-12);  // chi2 with 2 dof: e^(-x/2)
    // Tables of chi-square with 10 dof: 5 % above 18.307, 1 % above 23.209.
    EXPECT_NEAR(gamma_q(5.0, 18.307 / 2), 0.05, 1e-4);
    EXPECT_NEAR(gamma_q(5.0, 23.209 / 2), 0.01, 1e-4);
}

float3 direction(double theta, double phi) {
    return make_float3(float(std::sin(theta) * std::cos(phi)),
                       float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

/// The p-value of the hypothesis that bsdf_sample(sampled) draws its directions with density
/// bsdf_pdf(expected), from kSamples samples binned in (theta, phi) over the sphere.
double chi2_p_value(const Bsdf& sampled, const Bsdf& expected_bsdf, float3 wo,
                    std::string* report) {
    constexpr int kTheta = 20, kPhi = 40, kSub = 24;
    constexpr long kSamples = 1000000;
    std::vector<double> observed(kTheta * kPhi, 0), expected(kTheta * kPhi, 0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const double dt = M_PI / kTheta, dp = 2 * M_PI / kPhi;
    for (long i = 0; i < kSamples; ++i) {
        const float u1 = u(rng), u2 = u(rng), u3 = u(rng);
        const pathtracer::BsdfSample s = pathtracer::bsdf_sample(sampled, wo, u1, u2, u3);
        if (s.pdf <= 0) continue;
        const float3 w = normalize(s.wi);
        const double theta = std::acos(std::clamp(double(w.z), -1.0, 1.0));
        double phi = std::atan2(double(w.y), double(w.x));
        if (phi < 0) phi += 2 * M_PI;
        const int ti = std::min(int(theta / dt), kTheta - 1);
        const int pi = std::min(int(phi / dp), kPhi - 1);
        observed[ti * kPhi + pi] += 1;
    }
    // The pdf integrated over each bin (midpoint rule on a sub-grid, sin theta dtheta dphi).
    for (int ti = 0; ti < kTheta; ++ti)
        for (int pi = 0; pi < kPhi; ++pi) {
            double sum = 0;
            for (int a = 0; a < kSub; ++a)
                for (int b = 0; b < kSub; ++b) {
                    const double theta = (ti + (a + 0.5) / kSub) * dt;
                    const double phi = (pi + (b + 0.5) / kSub) * dp;
                    sum += pathtracer::bsdf_pdf(expected_bsdf, wo, direction(theta, phi)) *
                           std::sin(theta);
                }
            expected[ti * kPhi + pi] = sum * dt * dp / (kSub * kSub) * kSamples;
        }
    // Pool the cells expected to hold fewer than 5 samples (Mitsuba's chi2 test does the same).
    std::vector<int> order(observed.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
    double chi2 = 0, pool_o = 0, pool_e = 0;
    int dof = 0;
    for (int i : order) {
        if (expected[i] == 0) {
            if (observed[i] > 0) {
                if (report) *report = "samples in a cell of zero probability";
                return 0;
            }
            continue;
        }
        if (expected[i] < 5) {
            pool_o += observed[i];
            pool_e += expected[i];
            continue;
        }
        const double d = observed[i] - expected[i];
        chi2 += d * d / expected[i];
        ++dof;
    }
    if (pool_e > 0) {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        ++dof;
    }
    --dof;
    if (report)
        *report = "chi2 = " + std::to_string(chi2) + " with " + std::to_string(dof) + " dof";
    return gamma_q(dof / 2.0, chi2 / 2.0);
}

Bsdf make_bsdf(unsigned kind, float alpha, float eta = 1.5f) {
    return Bsdf{kind, make_float3(0.7f, 0.5f, 0.3f), make_float3(0.9f, 0.6f, 0.3f), alpha, eta};
}

void expect_sampling_matches_pdf(const Bsdf& bsdf, const char* what) {
    for (float theta_o : {0.3f, 1.2f}) {
        const float3 wo = direction(theta_o, 0.4);
        std::string report;
        const double p = chi2_p_value(bsdf, bsdf, wo, &report);
        // 1 % significance, Sidak-corrected for the two directions (as Mitsuba's tests).
        EXPECT_GT(p, 1.0 - std::pow(0.99, 1.0 / 2))
            << what << " at theta_o " << theta_o << ": " << report;
    }
}

TEST(ChiSquare, LambertSamplesItsPdf) {
    expect_sampling_matches_pdf(make_bsdf(pathtracer::kLambert, 1), "Lambert");
}
TEST(ChiSquare, GgxMetalSamplesItsPdfAtTwoRoughnesses) {
    expect_sampling_matches_pdf(make_bsdf(pathtracer::kMetal, 0.5f * 0.5f), "metal, roughness 0.5");
    expect_sampling_matches_pdf(make_bsdf(pathtracer::kMetal, 0.8f * 0.8f), "metal, roughness 0.8");
}
TEST(ChiSquare, CoatedSamplesItsPdf) {
    expect_sampling_matches_pdf(make_bsdf(pathtracer::kCoated, 0.4f * 0.4f), "coated");
}

TEST(ChiSquare, AWrongPdfIsRejected) {
    // The test must be able to fail: GGX samples of roughness 0.5 against the pdf of 0.55,
    // and Lambert samples against the coated pdf.
    const float3 wo = direction(0.5, 0.0);
    std::string report;
    EXPECT_LT(chi2_p_value(make_bsdf(pathtracer::kMetal, 0.25f),
                           make_bsdf(pathtracer::kMetal, 0.55f * 0.55f), wo, &report),
              1e-6)
        << report;
    EXPECT_LT(chi2_p_value(make_bsdf(pathtracer::kLambert, 1), make_bsdf(pathtracer::kCoated, 0.2f),
                           wo, &report),
              1e-6)
        << report;
}

TEST(ChiSquare, EvalOverPdfIsTheSampleWeight) {
    // weight = f cos / pdf for every sampled direction, the identity the path loop relies on.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (unsigned kind : {pathtracer::kLambert, pathtracer::kMetal, pathtracer::kCoated}) {
        const Bsdf bsdf = make_bsdf(kind, 0.2f);
        for (int i = 0; i < 1000; ++i) {
            const float3 wo = direction(1.3 * u(rng), 6.28 * u(rng));
            const auto s = pathtracer::bsdf_sample(bsdf, wo, u(rng), u(rng), u(rng));
            if (s.pdf <= 0) continue;
            const float3 f = pathtracer::bsdf_eval(bsdf, wo, s.wi) * (s.wi.z / s.pdf);
            EXPECT_NEAR(s.weight.x, f.x, 1e-4f * std::max(1.0f, f.x));
        }
    }
}

TEST(Dielectric, ReflectsWithTheFresnelProbabilityAndRefractsBySnell) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float eta : {1.5f, 1.0f / 1.5f})
        for (float cos_i : {0.95f, 0.6f, 0.2f}) {
            const Bsdf glass = make_bsdf(pathtracer::kDielectric, 0, eta);
            const float sin_i = std::sqrt(1 - cos_i * cos_i);
            const float3 wo = make_float3(sin_i, 0, cos_i);
            const float fresnel = pathtracer::fresnel_dielectric(cos_i, eta);
            const int n = 200000;
            int reflected = 0;
            for (int i = 0; i < n; ++i) {
                const auto s = pathtracer::bsdf_sample(glass, wo, u(rng), u(rng), u(rng));
                ASSERT_TRUE(s.delta);
                if (s.wi.z > 0) {
                    ++reflected;
                    EXPECT_NEAR(s.wi.x, -sin_i, 1e-5f);
                    EXPECT_FLOAT_EQ(s.weight.x, 1.0f);
                } else {
                    // Snell: sin_t = sin_i / eta, on the far side of the interface.
                    EXPECT_NEAR(-s.wi.x, sin_i / eta, 1e-4f);
                    EXPECT_NEAR(s.weight.x, 1.0f / (eta * eta), 1e-5f);
                }
            }
            const double sigma = std::sqrt(fresnel * (1 - fresnel) / n);
            EXPECT_NEAR(double(reflected) / n, fresnel, 5 * sigma + 1e-9)
                << "eta " << eta << ", cos " << cos_i;
        }
    // Fresnel at normal incidence ((eta - 1) / (eta + 1))^2 and total internal reflection.
    EXPECT_NEAR(pathtracer::fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6f);
    EXPECT_EQ(pathtracer::fresnel_dielectric(0.2f, 1.0f / 1.5f), 1.0f);
}

// ---- rendering: convergence, and NEE + MIS against BSDF sampling -------------------------------
/// Root-mean-square difference below the top quarter of the image: the light's edge pixels
/// (a coverage of radiance 17 or 0) would dominate the sum and make it a count of few events.
double rmse(const RenderResult& a, const RenderResult& b) {
    double sum = 0;
    const size_t first = size_t(a.image.height / 4) * a.image.width;
    for (size_t i = first; i < a.image.pixels.size(); ++i) {
        const float3 d = a.image.pixels[i] - b.image.pixels[i];
        sum += dot(d, d) / 3;
    }
    return std::sqrt(sum / double(a.image.pixels.size() - first));
}

TEST(PathTracer, ErrorFallsAsOneOverTheSquareRootOfTheSamples) {
    // Independent streams (seeds) for the reference and the two test images.
    const RenderResult reference = render("cornell", 32, 1024, {{"seed", "1"}});
    const RenderResult low = render("cornell", 32, 16, {{"seed", "2"}});
    const RenderResult high = render("cornell", 32, 64, {{"seed", "3"}});
    const double ratio = rmse(low, reference) / rmse(high, reference);
    // sqrt(64 / 16) = 2; the reference's own noise lowers it to about 1.95.
    EXPECT_GT(ratio, 1.7) << "ratio " << ratio;
    EXPECT_LT(ratio, 2.3) << "ratio " << ratio;
}

TEST(PathTracer, NextEventEstimationWithMisMatchesBsdfSamplingInTheMean) {
    for (const char* scene : {"cornell", "cornell-materials"}) {
        const RenderResult mis = render(scene, 24, 256, {{"nee", "1"}, {"seed", "4"}});
        // BSDF sampling alone rarely finds the small light: its image mean has a standard
        // deviation of about 1.4 % at 2048 spp (measured over seeds); 4 % is 3 sigma, and
        // emitters counted by both strategies without MIS would be off by tens of percent.
        const RenderResult bsdf = render(scene, 24, 2048, {{"nee", "0"}, {"seed", "5"}});
        EXPECT_EQ(mis.report.exception_count(), 0u);
        const float3 a = mean_of(mis, 0, 0, 24, 24), b = mean_of(bsdf, 0, 0, 24, 24);
        EXPECT_NEAR(a.x / b.x, 1.0f, 0.04f) << scene;
        EXPECT_NEAR(a.y / b.y, 1.0f, 0.04f) << scene;
        EXPECT_NEAR(a.z / b.z, 1.0f, 0.04f) << scene;
    }
}

TEST(PathTracer, BadOptionsAreClearErrors) {
    try {
        render("cornell", 8, 1, {{"max_depth", "0"}});
        FAIL();
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("max_depth"), std::string::npos) << e.what();
    }
    try {
        render("cornell", 8, 1, {{"nee", "yes"}});
        FAIL();
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("--set nee=yes"), std::string::npos) << e.what();
    }
}

}  // namespace
