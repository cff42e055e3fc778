// The clamps of a ray's reciprocal direction that both CPU traversals share (the
// single-ray loop, triangle_traverse.cpp, and the streams, triangle_stream.cpp), so that
// both see the same slabs: 1/d is clamped to +-min(kMaxInverse, kMaxOverInverse / max(|o|, 1)),
// which keeps |1/d| and |o/d| finite wherever the origin is (far beyond any t a ray asks
// about). 1/(+-0) is +-inf, which the clamp turns into +-limit.
#pragma once

namespace lucent::accel {

constexpr float kMaxInverse = 1e20f;
constexpr float kMaxOverInverse = 1e37f;

}  // namespace lucent::accel
