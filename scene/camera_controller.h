// The viewer's camera: orbit, pan and zoom about a target, and a fly mode that moves eye and
// target together. Pure math (no window), so it is tested like the rest of scene/.
#pragma once

#include "scene/scene.h"

namespace lucent::scene {

class CameraController {
  public:
    /// Starts at `start`; its look point becomes the orbit's target.
    explicit CameraController(const Camera& start);

    const Camera& camera() const { return m_camera; }
    /// Distance from the eye to the target.
    float distance() const;

    /// Turns the eye about the target: `yaw` radians about the up axis, `pitch` radians
    /// towards it. The pitch stops short of the poles so that the view never flips.
    void orbit(float yaw, float pitch);
    /// Moves eye and target in the image plane, by fractions of the view's height at the
    /// target (x right, y up): a drag across the window moves the scene with the cursor.
    void pan(float x, float y);
    /// Scales the eye's distance to the target (below 1: closer), down to closest_distance().
    void zoom(float factor);
    /// How close zoom() comes to the target: kClosestFraction of the starting distance, or 16
    /// float spacings of the target's coordinates where those are coarser (far from 0).
    float closest_distance() const;
    static constexpr float kClosestFraction = 1e-5f;
    /// Moves eye and target together along the view direction, its right and the up axis.
    void fly(float forward, float right, float up);
    /// Back to the start.
    void reset() { m_camera = m_start; }

  private:
    Camera m_start, m_camera;
};

}  // namespace lucent::scene
