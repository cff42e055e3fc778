// FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström and Fairchild, "FLIP: A
// Difference Evaluator for Alternating Images", HPG 2020): the perceived difference between
// a reference image and a test image flipped back and forth, per pixel in [0, 1], for an
// observer seeing `pixels_per_degree` pixels per degree of visual angle. This is LDR-FLIP:
// the images are compared as displayed, linear RGB clamped to [0, 1].
#pragma once

#include <vector>

#include "scene/image_io.h"

namespace lucent::scene {

/// The paper's default observer: a 0.7 m wide monitor of 3840 pixels seen from 0.7 m.
inline constexpr double kFlipPixelsPerDegree = 3840.0 * 3.14159265358979323846 / 180.0;

/// FLIP's error per pixel (row 0 at the top). The images must have the same size; throws
/// lucent::Error otherwise, or for pixels_per_degree outside [1, 1000].
std::vector<float> flip_error_map(const Image& reference, const Image& test,
                                  double pixels_per_degree = kFlipPixelsPerDegree);

}  // namespace lucent::scene
