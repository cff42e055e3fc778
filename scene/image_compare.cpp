#include "scene/image_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "lucent/error.h"

namespace lucent::scene {

namespace {

void require_finite(const Image& image, const char* which) {
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const float3 p = image.pixels[i];
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) continue;
        if (bad++ == 0) first = i;
    }
    if (bad)
        throw Error(std::string("compare: the ") + which + " image has " + std::to_string(bad) +
                    " pixels that are not finite (NaN or infinite; the first at x " +
                    std::to_string(first % image.width) + ", y " +
                    std::to_string(first / image.width) + ")");
}

}  // namespace

ImageComparison compare_images(const Image& reference, const Image& test, double pixels_per_degree) {
    for (const Image* image : {&reference, &test})
        if (image->pixels.empty() || image->pixels.size() != size_t(image->width) * image->height)
            throw Error(std::string("compare: the ") + (image == &reference ? "reference" : "test") +
                        " image has " + std::to_string(image->pixels.size()) + " pixels for " +
                        std::to_string(image->width) + "x" + std::to_string(image->height) +
                        "; an image needs width x height pixels, at least one");
    require_finite(reference, "reference");
    require_finite(test, "test");
    ImageComparison c;
    c.flip = flip_error_map(reference, test, pixels_per_degree);  // checks the sizes
    c.width = reference.width;
    c.height = reference.height;
    double squared = 0, relative = 0, clamped = 0;
    for (size_t i = 0; i < reference.pixels.size(); ++i) {
        const float r[3] = {reference.pixels[i].x, reference.pixels[i].y, reference.pixels[i].z};
        const float t[3] = {test.pixels[i].x, test.pixels[i].y, test.pixels[i].z};
        for (int k = 0; k < 3; ++k) {
            const double d = double(t[k]) - double(r[k]);
            squared += d * d;
            // Relative MSE as in Rousselle et al. 2011: 0.01 keeps dark pixels from dominating.
            relative += d * d / (double(r[k]) * r[k] + 0.01);
            const double dc = std::clamp(double(t[k]), 0.0, 1.0) - std::clamp(double(r[k]), 0.0, 1.0);
            clamped += dc * dc;
        }
    }
    const double n = 3.0 * double(reference.pixels.size());
    c.rmse = std::sqrt(squared / n);
    c.relmse = relative / n;
    c.psnr_db = clamped == 0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(n / clamped);
    double sum = 0;
    for (float f : c.flip) sum += f;
    c.flip_mean = sum / double(c.flip.size());
    std::vector<float> sorted = c.flip;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    c.flip_median = sorted[sorted.size() / 2];
    c.flip_max = *std::max_element(c.flip.begin(), c.flip.end());
    return c;
}

Image flip_image(const ImageComparison& comparison) {
    Image image;
    image.width = comparison.width;
    image.height = comparison.height;
    for (float f : comparison.flip) image.pixels.push_back(make_float3(f));
    return image;
}

}  // namespace lucent::scene
