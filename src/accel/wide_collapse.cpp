#include "accel/wide_collapse.h"

#include <algorithm>

namespace lucent::accel {

namespace {

float half_area(float3 lo, float3 hi) {
    const float3 d = hi - lo;
    if (!(d.x >= 0.0f)) return 0.0f;
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

}  // namespace

float WideCollapse::best_children(uint32_t n, int& left_share) const {
    const BvhNode& b = m_binary.nodes()[n];
    float best = kInfinity;
    left_share = 1;
    for (int j = 1; j < kWideArity; ++j) {
        const float c = m_cover[b.first][j] + m_cover[b.first + 1][kWideArity - j];
        if (c < best) best = c, left_share = j;
    }
    return best;
}

// Children have larger indices than their parent, so one backward sweep is bottom-up.
void WideCollapse::plan() {
    const auto& bn = m_binary.nodes();
    m_cover.assign(bn.size(), {});
    m_split.assign(bn.size(), {});
    for (size_t i = bn.size(); i-- > 0;) {
        const BvhNode& b = bn[i];
        const float area = half_area(b.lo, b.hi);
        if (b.count > 0) {
            m_cover[i].fill(area * m_leaf_cost[i]);
            continue;
        }
        int share;
        const float self = area + best_children(uint32_t(i), share);
        m_cover[i][1] = self;
        for (int k = 2; k <= kWideArity; ++k) {
            m_cover[i][k] = self;
            m_split[i][k] = 0;
            for (int j = 1; j < k; ++j) {
                const float c = m_cover[b.first][j] + m_cover[b.first + 1][k - j];
                if (c < m_cover[i][k]) m_cover[i][k] = c, m_split[i][k] = uint8_t(j);
            }
        }
    }
}

void WideCollapse::collect(uint32_t n, int k, uint32_t* kids, int& count) const {
    const int j = m_split[n][k];
    if (j == 0) {
        kids[count++] = n;
        return;
    }
    const uint32_t first = m_binary.nodes()[n].first;
    collect(first, j, kids, count);
    collect(first + 1, k - j, kids, count);
}

int WideCollapse::children(uint32_t n, uint32_t (&kids)[kWideArity]) const {
    const BvhNode& b = m_binary.nodes()[n];
    int count = 0;
    if (b.count > 0) {
        kids[count++] = n;
        return count;
    }
    int share;
    best_children(n, share);
    collect(b.first, share, kids, count);
    collect(b.first + 1, kWideArity - share, kids, count);
    return count;
}

}  // namespace lucent::accel
