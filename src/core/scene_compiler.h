// Turns the node graph into a CompiledScene: finds every node reachable from the
// programs' variables, checks the graph (cycles, transforms, types), resolves each
// program's variables in the OptiX scope order and packs its record, then builds or
// refits the acceleration structures that changed.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/compiled_scene.h"
#include "core/context_state.h"

namespace lucent::core {

/// The scopes a program's variables are looked up in, first match wins.
struct ScopeChain {
    const VariableScope* scopes[4] = {};
    int count = 0;
    ScopeChain& then(const VariableScope* s) {
        if (s) scopes[count++] = s;
        return *this;
    }
};

class SceneCompiler {
  public:
    /// host_traversal: the backend traverses on the host, so GeometryGroups with
    /// Builder::kGpuHploc need their host BVH too (else only their bounds).
    SceneCompiler(const ContextState& state, AccelCache& cache, bool host_traversal = true)
        : m_state(state), m_cache(cache), m_host_traversal(host_traversal) {}

    /// Full compile for a launch.
    std::unique_ptr<CompiledScene> compile();
    /// Every check of compile(), without building acceleration structures.
    void validate_only();
    /// Time spent building/refitting acceleration structures in compile().
    double accel_ms() const { return m_accel_ms; }

  private:
    void compile_graph();
    unsigned node_index(const std::shared_ptr<Node>& node);
    unsigned instance_index(const GeometryInstance& instance);
    void compile_node(unsigned index);
    void compile_instance(unsigned index);
    void check_cycles() const;
    void check_types() const;
    void find_reached_instances();
    void build_accelerations();
    void build_geometry_accel(CompiledNode& node);
    Aabb node_bounds(unsigned index, std::vector<int>& state);

    // record_packer.cpp
    CompiledProgram pack(const std::shared_ptr<Program>& program, const ScopeChain& chain,
                         const std::string& owner,
                         std::vector<const Buffer*>* output_buffers = nullptr);
    /// `label` names the program whose record holds the field (CompiledProgram::label).
    void pack_field(const FieldInfo& field, const VariableValue& value, unsigned char* dst,
                    const std::string& label, std::vector<const Buffer*>* output_buffers);
    std::shared_ptr<PackedRecord> pack_callable(const std::shared_ptr<Program>& program,
                                                const std::string& where);

    const ContextState& m_state;
    AccelCache& m_cache;
    bool m_host_traversal = true;
    std::vector<const Buffer*> m_rebuild_inputs;  // see CompiledScene::rebuild_inputs
    std::unique_ptr<CompiledScene> m_scene;
    std::map<const Node*, unsigned> m_node_ids;
    std::map<const GeometryInstance*, unsigned> m_instance_ids;
    std::map<const Program*, std::shared_ptr<PackedRecord>> m_callables;
    std::vector<std::shared_ptr<Node>> m_node_refs;  // keep nodes alive during compile
    std::vector<unsigned> m_node_queue;
    std::vector<std::vector<bool>> m_reaches;  // per ray type with roots: instance reached?
    double m_accel_ms = 0;
};

}  // namespace lucent::core
