// Generic traversal of lucent::accel::Bvh (included from bvh.h).
#pragma once

namespace lucent::accel {

namespace detail {
/// Slab test: entry distance of the ray into [lo, hi] or +inf when it misses [tmin, tmax].
inline float slab_entry(const BvhNode& n, float3 org, float3 inv_dir, float tmin, float tmax) {
    float tx0 = (n.lo.x - org.x) * inv_dir.x, tx1 = (n.hi.x - org.x) * inv_dir.x;
    float ty0 = (n.lo.y - org.y) * inv_dir.y, ty1 = (n.hi.y - org.y) * inv_dir.y;
    float tz0 = (n.lo.z - org.z) * inv_dir.z, tz1 = (n.hi.z - org.z) * inv_dir.z;
    float t_near =
        lc_max(lc_max(lc_min(tx0, tx1), lc_min(ty0, ty1)), lc_max(lc_min(tz0, tz1), tmin));
    float t_far =
        lc_min(lc_min(lc_max(tx0, tx1), lc_max(ty0, ty1)), lc_min(lc_max(tz0, tz1), tmax));
    // 1 + 2^-21 on the far side: rounding never culls a box the ray touches, those of zero
    // thickness included (Ize 2013: the three roundings on each side need 1 + 7u, u = 2^-24).
    // The GPU's box test for Groups (trace.cuh) takes the same margin.
    return t_near <= t_far * (1.0f + 0x1p-21f) ? t_near : kInfinity * 2.0f;
}
inline float safe_inverse(float d) {
    return d != 0.0f ? 1.0f / d : (std::signbit(d) ? -kInfinity * 1e8f : kInfinity * 1e8f);
}
}  // namespace detail

template <class Visit>
void Bvh::traverse(float3 origin, float3 direction, float tmin, const float& tmax,
                   Visit&& visit) const {
    if (m_nodes.empty()) return;
    float3 inv = make_float3(detail::safe_inverse(direction.x), detail::safe_inverse(direction.y),
                             detail::safe_inverse(direction.z));
    uint32_t stack[64];
    int top = 0;
    if (detail::slab_entry(m_nodes[0], origin, inv, tmin, tmax) > tmax) return;
    uint32_t current = 0;
    for (;;) {
        const BvhNode& node = m_nodes[current];
        if (node.count > 0) {
            for (uint32_t i = 0; i < node.count; ++i)
                if (visit(m_prim_order[node.first + i])) return;
        } else {
            uint32_t a = node.first, b = node.first + 1;
            float ta = detail::slab_entry(m_nodes[a], origin, inv, tmin, tmax);
            float tb = detail::slab_entry(m_nodes[b], origin, inv, tmin, tmax);
            if (tb < ta) {
                std::swap(a, b);
                std::swap(ta, tb);
            }
            if (ta <= tmax) {
                if (tb <= tmax) stack[top++] = b;
                current = a;
                continue;
            }
        }
        if (top == 0) return;
        current = stack[--top];
    }
}

}  // namespace lucent::accel
