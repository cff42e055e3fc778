// OBJ faces index positions, normals and texture coordinates separately; a mesh's vertex is
// one (position, normal, uv) triple. Most files use each position with one normal and uv,
// so a table indexed by position answers in one lookup, and only a position met again with
// another normal or uv goes to a hash map (a std::map of every triple took 15 % of a 75 MB
// OBJ's load).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace lucent::scene {

class VertexUnifier {
  public:
    /// For files of `positions` positions.
    explicit VertexUnifier(size_t positions) : m_stamp(positions, 0), m_slot(positions, 0) {}

    /// Starts a mesh: the triples seen so far belong to the one before.
    void next_mesh() {
        ++m_mesh;
        m_normal_uv.clear();
        m_repeated.clear();
    }

    /// The mesh vertex of (position, normal, uv) (normal and uv -1 when absent), and whether
    /// it is new: then it is `count`, the mesh's vertex count so far, and the caller adds it.
    std::pair<unsigned, bool> find(int position, int normal, int uv, unsigned count) {
        const std::pair<int, int> rest{normal, uv};
        if (m_stamp[size_t(position)] != m_mesh) {
            m_stamp[size_t(position)] = m_mesh;
            m_slot[size_t(position)] = count;
            m_normal_uv.push_back(rest);
            return {count, true};
        }
        const unsigned first = m_slot[size_t(position)];
        if (m_normal_uv[first] == rest) return {first, false};
        const auto [it, inserted] = m_repeated.emplace(Triple{position, normal, uv}, count);
        if (inserted) m_normal_uv.push_back(rest);
        return {it->second, inserted};
    }

  private:
    struct Triple {
        int position, normal, uv;
        bool operator==(const Triple&) const = default;
    };
    struct TripleHash {
        size_t operator()(const Triple& t) const {
            return (uint64_t(uint32_t(t.position)) * 0x9E3779B97F4A7C15ull) ^
                   (uint64_t(uint32_t(t.normal)) << 32 | uint32_t(t.uv)) * 0xC2B2AE3D27D4EB4Full;
        }
    };
    uint32_t m_mesh = 0;
    std::vector<uint32_t> m_stamp;                  // the mesh that last used each position
    std::vector<unsigned> m_slot;                   // its first vertex in that mesh
    std::vector<std::pair<int, int>> m_normal_uv;   // per mesh vertex
    std::unordered_map<Triple, unsigned, TripleHash> m_repeated;
};

}  // namespace lucent::scene
