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

void WideCollapse::children_by_octant(uint32_t n, uint32_t (&slot_kid)[kWideArity]) const {
    static_assert(kWideArity == 8, "one slot per corner of the box");
    uint32_t kids[kWideArity];
    const int count = children(n, kids);
    const auto& bn = m_binary.nodes();
    const float3 center = 0.5f * (bn[n].lo + bn[n].hi);
    float score[kWideArity][kWideArity];  // [child][slot]
    for (int c = 0; c < count; ++c) {
        const float3 d = 0.5f * (bn[kids[c]].lo + bn[kids[c]].hi) - center;
        for (int s = 0; s < kWideArity; ++s)
            score[c][s] = (s & 1 ? d.x : -d.x) + (s & 2 ? d.y : -d.y) + (s & 4 ? d.z : -d.z);
    }
    for (uint32_t& k : slot_kid) k = kNoChild;
    bool placed[kWideArity] = {};
    for (int round = 0; round < count; ++round) {
        int best_c = -1, best_s = -1;
        for (int c = 0; c < count; ++c) {
            if (placed[c]) continue;
            for (int s = 0; s < kWideArity; ++s)
                if (slot_kid[s] == kNoChild && (best_c < 0 || score[c][s] > score[best_c][best_s]))
                    best_c = c, best_s = s;
        }
        slot_kid[best_s] = kids[best_c];
        placed[best_c] = true;
    }
}

}  // namespace lucent::accel
