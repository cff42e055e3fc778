// The viewer's camera controller (scene/camera_controller.h): each move keeps what it
// promises (orbit: the target and the distance; pan: the view direction; zoom: the target).
#include <gtest/gtest.h>

#include <cmath>

#include "scene/camera_controller.h"

namespace {

using lucent::scene::Camera;
using lucent::scene::CameraController;

Camera start_camera() {
    Camera c;
    c.eye = make_float3(0.0f, 0.0f, 10.0f);
    c.look = make_float3(0.0f, 0.0f, 0.0f);
    c.up = make_float3(0.0f, 1.0f, 0.0f);
    c.fov_degrees = 60.0f;
    return c;
}

void expect_near(float3 a, float3 b, float tolerance = 1e-4f) {
    EXPECT_NEAR(a.x, b.x, tolerance);
    EXPECT_NEAR(a.y, b.y, tolerance);
    EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(CameraController, YawTurnsTheEyeAboutTheUpAxisAtTheSameDistance) {
    CameraController c(start_camera());
    c.orbit(float(M_PI) / 2, 0.0f);
    EXPECT_NEAR(c.distance(), 10.0f, 1e-4f);
    expect_near(c.camera().look, make_float3(0.0f, 0.0f, 0.0f));
    EXPECT_NEAR(c.camera().eye.y, 0.0f, 1e-4f);
    EXPECT_NEAR(std::fabs(c.camera().eye.x), 10.0f, 1e-3f);  // a quarter turn
}

TEST(CameraController, PitchRaisesTheEyeAndStopsShortOfThePole) {
    CameraController c(start_camera());
    c.orbit(0.0f, 0.5f);
    EXPECT_NEAR(c.distance(), 10.0f, 1e-4f);
    EXPECT_NEAR(c.camera().eye.y, 10.0f * std::sin(0.5f), 1e-3f);
    c.orbit(0.0f, 10.0f);  // far past the pole
    EXPECT_GT(c.camera().eye.z, 0.0f) << "the eye went over the top";
    EXPECT_LT(c.camera().eye.y, 10.0f);
    EXPECT_NEAR(c.distance(), 10.0f, 1e-3f);
}

TEST(CameraController, PanMovesEyeAndTargetTogetherByTheViewHeight) {
    CameraController c(start_camera());
    c.pan(0.5f, 0.0f);  // half the view's height at the target, to the right
    const float height = 2.0f * 10.0f * std::tan(30.0f * float(M_PI) / 180.0f);
    // The scene follows the cursor, so the camera moves left (-x).
    expect_near(c.camera().look, make_float3(-0.5f * height, 0.0f, 0.0f), 1e-3f);
    expect_near(c.camera().eye, make_float3(-0.5f * height, 0.0f, 10.0f), 1e-3f);
    c.pan(0.0f, 0.25f);
    EXPECT_NEAR(c.camera().look.y, -0.25f * height, 1e-3f);
}

TEST(CameraController, ZoomScalesTheDistanceAndNeverReachesTheTarget) {
    CameraController c(start_camera());
    c.zoom(0.5f);
    expect_near(c.camera().eye, make_float3(0.0f, 0.0f, 5.0f));
    for (int i = 0; i < 200; ++i) c.zoom(0.1f);
    EXPECT_GT(c.distance(), 0.0f);
    EXPECT_GT(c.camera().eye.z, 0.0f);
}

/// start_camera() scaled by `scale` about 0, then moved by `offset` on every axis.
Camera placed_camera(float scale, float offset) {
    Camera c = start_camera();
    c.eye = c.eye * scale + make_float3(offset);
    c.look = c.look * scale + make_float3(offset);
    return c;
}

TEST(CameraController, ZoomComesAsCloseAtEveryScale) {
    // The scene 1e-6 as large, its camera alike (10 micrometres from the target): the same
    // wheel steps give the same share of the starting distance. An absolute floor (1e-4)
    // stopped the first step here at 1e-4, ten times the starting distance.
    for (const float scale : {1.0f, 1e-6f, 1e6f}) {
        CameraController c(placed_camera(scale, 0.0f));
        c.zoom(0.1f);
        EXPECT_NEAR(c.distance() / scale, 1.0f, 1e-5f) << "scale " << scale;
        for (int i = 0; i < 200; ++i) c.zoom(0.1f);
        EXPECT_NEAR(c.distance() / (10.0f * scale), CameraController::kClosestFraction,
                    1e-3f * CameraController::kClosestFraction)
            << "scale " << scale;
        EXPECT_GT(c.camera().eye.z, c.camera().look.z) << "scale " << scale;
    }
}

TEST(CameraController, ZoomAtOffset1e6KeepsTheEyeApartAndTheViewDirection) {
    // 10 from a target at (1e6, 1e6, 1e6), where floats are 1/16 apart: half the distance is
    // 5 (an absolute floor of 1e-4 (1 + |look|) = 173 threw the eye back to 173), and the
    // closest zoom stops 16 spacings (1) from the target, still looking along -z.
    CameraController c(placed_camera(1.0f, 1e6f));
    c.zoom(0.5f);
    EXPECT_NEAR(c.distance(), 5.0f, 0.0625f);
    for (int i = 0; i < 200; ++i) c.zoom(0.1f);
    EXPECT_GT(c.distance(), 0.0f);
    EXPECT_LE(c.distance(), 1.0f + 0.0625f);
    EXPECT_NEAR(c.closest_distance(), 16.0f * 0.0625f, 1e-6f);
    const float3 view = normalize(c.camera().look - c.camera().eye);
    expect_near(view, make_float3(0.0f, 0.0f, -1.0f), 1e-3f);
}

TEST(CameraController, FlyMovesAlongTheViewAndResetReturns) {
    CameraController c(start_camera());
    c.fly(2.0f, 1.0f, 0.5f);  // forward is -z, right is +x
    expect_near(c.camera().eye, make_float3(1.0f, 0.5f, 8.0f));
    expect_near(c.camera().look, make_float3(1.0f, 0.5f, -2.0f));
    EXPECT_NEAR(c.distance(), 10.0f, 1e-4f);
    c.reset();
    expect_near(c.camera().eye, start_camera().eye);
}

}  // namespace
