// How far a test image is from a reference: RMSE, relative MSE, PSNR and FLIP, the figures
// renderer papers and tools (pbrt's imgtool, Mitsuba's tests, FLIP) report.
#pragma once

#include <vector>

#include "scene/flip.h"
#include "scene/image_io.h"

namespace lucent::scene {

struct ImageComparison {
    unsigned width = 0, height = 0;
    double rmse = 0;     // root mean square difference of linear RGB, all channels
    double relmse = 0;   // mean of (test - ref)^2 / (ref^2 + 0.01) per channel
    double psnr_db = 0;  // 10 log10(1 / MSE) of the images clamped to [0, 1]; inf: identical
    double flip_mean = 0, flip_median = 0, flip_max = 0;  // of the FLIP map
    std::vector<float> flip;  // FLIP per pixel, row 0 at the top
};

/// Compares two images of one size. Throws lucent::Error for sizes that differ or for a
/// pixel that is not finite (naming the image, the count and the first such pixel).
ImageComparison compare_images(const Image& reference, const Image& test,
                               double pixels_per_degree = kFlipPixelsPerDegree);

/// The FLIP map as a grey image: each pixel's FLIP value in all three channels.
Image flip_image(const ImageComparison& comparison);

}  // namespace lucent::scene
