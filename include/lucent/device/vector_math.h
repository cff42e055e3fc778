// Small vector-math header shared by host code, CPU programs and (later) NVRTC.
//
// Under CUDA the vector types come from CUDA's own headers; elsewhere we declare
// structs with the same names, members and alignment, so a record packed on the
// host has the same layout on both backends. Only operators and helpers are ours.
#pragma once

#include "lucent/device/platform.h"

#if !LUCENT_CUDA_TYPES
#include <cmath>
#include <cstdint>

// Same layout and alignment as CUDA's vector_types.h.
struct alignas(8) float2 {
    float x, y;
};
struct float3 {
    float x, y, z;
};
struct alignas(16) float4 {
    float x, y, z, w;
};
struct alignas(8) int2 {
    int x, y;
};
struct int3 {
    int x, y, z;
};
struct alignas(16) int4 {
    int x, y, z, w;
};
struct alignas(8) uint2 {
    unsigned x, y;
};
struct uint3 {
    unsigned x, y, z;
};
struct alignas(16) uint4 {
    unsigned x, y, z, w;
};
struct alignas(4) uchar4 {
    unsigned char x, y, z, w;
};

inline float2 make_float2(float x, float y) {
    return {x, y};
}
inline float3 make_float3(float x, float y, float z) {
    return {x, y, z};
}
inline float4 make_float4(float x, float y, float z, float w) {
    return {x, y, z, w};
}
inline int2 make_int2(int x, int y) {
    return {x, y};
}
inline int3 make_int3(int x, int y, int z) {
    return {x, y, z};
}
inline int4 make_int4(int x, int y, int z, int w) {
    return {x, y, z, w};
}
inline uint2 make_uint2(unsigned x, unsigned y) {
    return {x, y};
}
inline uint3 make_uint3(unsigned x, unsigned y, unsigned z) {
    return {x, y, z};
}
inline uint4 make_uint4(unsigned x, unsigned y, unsigned z, unsigned w) {
    return {x, y, z, w};
}
inline uchar4 make_uchar4(unsigned char x, unsigned char y, unsigned char z, unsigned char w) {
    return {x, y, z, w};
}
using std::sqrt;
#endif

// ---- scalar helpers -------------------------------------------------------
LUCENT_HD inline float lc_min(float a, float b) {
    return a < b ? a : b;
}
LUCENT_HD inline float lc_max(float a, float b) {
    return a > b ? a : b;
}
LUCENT_HD inline float clampf(float x, float lo, float hi) {
    return lc_min(lc_max(x, lo), hi);
}
LUCENT_HD inline float lerpf(float a, float b, float t) {
    return a + (b - a) * t;
}

// ---- float2 ----------------------------------------------------------------
LUCENT_HD inline float2 operator+(float2 a, float2 b) {
    return make_float2(a.x + b.x, a.y + b.y);
}
LUCENT_HD inline float2 operator-(float2 a, float2 b) {
    return make_float2(a.x - b.x, a.y - b.y);
}
LUCENT_HD inline float2 operator*(float2 a, float2 b) {
    return make_float2(a.x * b.x, a.y * b.y);
}
LUCENT_HD inline float2 operator*(float2 a, float s) {
    return make_float2(a.x * s, a.y * s);
}
LUCENT_HD inline float2 operator*(float s, float2 a) {
    return make_float2(a.x * s, a.y * s);
}
LUCENT_HD inline float2 operator/(float2 a, float s) {
    return make_float2(a.x / s, a.y / s);
}
LUCENT_HD inline float dot(float2 a, float2 b) {
    return a.x * b.x + a.y * b.y;
}

// ---- float3 ----------------------------------------------------------------
LUCENT_HD inline float3 make_float3(float s) {
    return make_float3(s, s, s);
}
LUCENT_HD inline float3 make_float3(float4 v) {
    return make_float3(v.x, v.y, v.z);
}
LUCENT_HD inline float4 make_float4(float3 v, float w) {
    return make_float4(v.x, v.y, v.z, w);
}
LUCENT_HD inline float3 operator-(float3 a) {
    return make_float3(-a.x, -a.y, -a.z);
}
LUCENT_HD inline float3 operator+(float3 a, float3 b) {
    return make_float3(a.x + b.x, a.y + b.y, a.z + b.z);
}
LUCENT_HD inline float3 operator-(float3 a, float3 b) {
    return make_float3(a.x - b.x, a.y - b.y, a.z - b.z);
}
LUCENT_HD inline float3 operator*(float3 a, float3 b) {
    return make_float3(a.x * b.x, a.y * b.y, a.z * b.z);
}
LUCENT_HD inline float3 operator/(float3 a, float3 b) {
    return make_float3(a.x / b.x, a.y / b.y, a.z / b.z);
}
LUCENT_HD inline float3 operator*(float3 a, float s) {
    return make_float3(a.x * s, a.y * s, a.z * s);
}
LUCENT_HD inline float3 operator*(float s, float3 a) {
    return make_float3(a.x * s, a.y * s, a.z * s);
}
LUCENT_HD inline float3 operator/(float3 a, float s) {
    return a * (1.0f / s);
}
LUCENT_HD inline float3& operator+=(float3& a, float3 b) {
    a = a + b;
    return a;
}
LUCENT_HD inline float3& operator-=(float3& a, float3 b) {
    a = a - b;
    return a;
}
LUCENT_HD inline float3& operator*=(float3& a, float3 b) {
    a = a * b;
    return a;
}
LUCENT_HD inline float3& operator*=(float3& a, float s) {
    a = a * s;
    return a;
}
LUCENT_HD inline float dot(float3 a, float3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
LUCENT_HD inline float3 cross(float3 a, float3 b) {
    return make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
LUCENT_HD inline float length(float3 a) {
    return sqrtf(dot(a, a));
}
LUCENT_HD inline float3 normalize(float3 a) {
    return a * (1.0f / sqrtf(dot(a, a)));
}
LUCENT_HD inline float3 fminf(float3 a, float3 b) {
    return make_float3(lc_min(a.x, b.x), lc_min(a.y, b.y), lc_min(a.z, b.z));
}
LUCENT_HD inline float3 fmaxf(float3 a, float3 b) {
    return make_float3(lc_max(a.x, b.x), lc_max(a.y, b.y), lc_max(a.z, b.z));
}
LUCENT_HD inline float max_component(float3 a) {
    return lc_max(a.x, lc_max(a.y, a.z));
}
LUCENT_HD inline float min_component(float3 a) {
    return lc_min(a.x, lc_min(a.y, a.z));
}
LUCENT_HD inline float3 clamp(float3 v, float lo, float hi) {
    return make_float3(clampf(v.x, lo, hi), clampf(v.y, lo, hi), clampf(v.z, lo, hi));
}
LUCENT_HD inline float3 lerp(float3 a, float3 b, float t) {
    return a + (b - a) * t;
}
/// Mirror reflection of incident direction i about normal n.
LUCENT_HD inline float3 reflect(float3 i, float3 n) {
    return i - 2.0f * dot(n, i) * n;
}
/// Refraction of unit direction i through unit normal n facing i (dot(i,n) < 0) with
/// relative index eta = n_from / n_to; false on total internal reflection.
LUCENT_HD inline bool refract(float3& t, float3 i, float3 n, float eta) {
    float cos_i = -dot(i, n);
    float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
    if (k < 0.0f) return false;
    t = eta * i + (eta * cos_i - sqrtf(k)) * n;
    return true;
}
/// Flip n so that it faces against direction d.
LUCENT_HD inline float3 faceforward(float3 n, float3 d) {
    return dot(n, d) < 0.0f ? n : -n;
}

// ---- float4 ----------------------------------------------------------------
LUCENT_HD inline float4 operator+(float4 a, float4 b) {
    return make_float4(a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w);
}
LUCENT_HD inline float4 operator*(float4 a, float s) {
    return make_float4(a.x * s, a.y * s, a.z * s, a.w * s);
}
LUCENT_HD inline float4 operator*(float s, float4 a) {
    return a * s;
}
