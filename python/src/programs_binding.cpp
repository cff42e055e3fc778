// Programs and program modules from Python: the modules compiled into the extension (the
// ray-query module, the samples' and the tutorial's), their programs and record fields, and
// the type names that buffers, variables and ray types are given by.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <set>
#include <vector>

#include "bindings.h"

namespace lucent::python {

namespace {

struct NamedType {
    const char* name;
    const TypeInfo* type;
};

const std::vector<NamedType>& builtin_types() {
    static const std::vector<NamedType> types = {
        {"float", &type_info_of<float>()},         {"float2", &type_info_of<float2>()},
        {"float3", &type_info_of<float3>()},       {"float4", &type_info_of<float4>()},
        {"int", &type_info_of<int>()},             {"int2", &type_info_of<int2>()},
        {"int3", &type_info_of<int3>()},           {"int4", &type_info_of<int4>()},
        {"uint", &type_info_of<unsigned>()},       {"uint2", &type_info_of<uint2>()},
        {"uint3", &type_info_of<uint3>()},         {"uint4", &type_info_of<uint4>()},
        {"uint8", &type_info_of<unsigned char>()}, {"matrix4x3", &type_info_of<Matrix4x3>()},
    };
    return types;
}

/// The structs the compiled modules' records (buffer elements, user data) and programs
/// (payloads, attributes) use.
std::vector<const TypeInfo*> module_types() {
    std::vector<const TypeInfo*> types;
    std::set<const void*> seen;
    auto add = [&](const TypeInfo* t) {
        if (t && seen.insert(t->tag).second) types.push_back(t);
    };
    for (const ModuleInfo* module : modules())
        for (const ProgramDesc* p : module->programs()) {
            add(p->payload);
            add(p->attributes);
            if (p->record)
                for (const FieldInfo& f : p->record->fields)
                    if (f.kind == FieldKind::kBuffer || f.kind == FieldKind::kUserData)
                        add(f.element);
        }
    return types;
}

}  // namespace

const TypeInfo& type_by_name(const std::string& name, const char* what) {
    for (const NamedType& t : builtin_types())
        if (name == t.name) return *t.type;
    std::string structs;
    for (const TypeInfo* t : module_types()) {
        if (t->name == name) return *t;
        bool builtin = false;
        for (const NamedType& b : builtin_types()) builtin = builtin || same_type(*b.type, *t);
        if (!builtin) structs += (structs.empty() ? "" : ", ") + std::string(t->name);
    }
    std::string names;
    for (const NamedType& t : builtin_types()) names += (names.empty() ? "" : ", ") + std::string(t.name);
    throw py::value_error(std::string(what) + ": no type '" + name + "'; the built-in types are " +
                          names + "; the compiled modules' structs are " + structs);
}

std::string type_name(const TypeInfo& type) {
    for (const NamedType& t : builtin_types())
        if (same_type(*t.type, type)) return t.name;
    return std::string(type.name);
}

void bind_programs(py::module_& m) {
    py::class_<ModuleInfo, std::unique_ptr<ModuleInfo, py::nodelete>>(
        m, "ModuleInfo", "A program module compiled into this extension.")
        .def_property_readonly("name", [](const ModuleInfo& mi) { return std::string(mi.name()); })
        .def_property_readonly("file", &ModuleInfo::file)
        .def_property_readonly("uses_occluded",
                               [](const ModuleInfo& mi) { return mi.uses(kUsesOccluded); })
        .def_property_readonly(
            "programs",
            [](const ModuleInfo& mi) {
                py::list names;
                for (const ProgramDesc* p : mi.programs()) names.append(std::string(p->name));
                return names;
            },
            "The names of its programs, as create_program takes them.")
        .def(
            "describe",
            [](const ModuleInfo& mi) {
                // One line per program: kind, name, record fields and payload.
                std::string text = "module " + std::string(mi.name()) + " (" + mi.file() + ")\n";
                for (const ProgramDesc* p : mi.programs()) {
                    text += "  " + std::string(program_kind_name(p->kind)) + " " +
                            std::string(p->name);
                    if (p->payload) text += ", payload " + type_name(*p->payload);
                    if (p->record && !p->record->fields.empty()) {
                        text += ", record {";
                        bool first = true;
                        for (const FieldInfo& f : p->record->fields) {
                            text += (first ? "" : ", ") + std::string(f.name) + ": " +
                                    field_kind_name(f.kind);
                            if (f.element) text += "<" + type_name(*f.element) + ">";
                            first = false;
                        }
                        text += "}";
                    }
                    text += "\n";
                }
                return text;
            },
            "Its programs with their kinds, records (the variables they read) and payloads.")
        .def("__repr__", [](const ModuleInfo& mi) {
            return "<lucent.ModuleInfo '" + std::string(mi.name()) + "'>";
        });

    m.def(
        "modules",
        []() {
            py::list list;
            for (const ModuleInfo* mi : modules())
                list.append(py::cast(mi, py::return_value_policy::reference));
            return list;
        },
        "The program modules compiled into this extension (ModuleInfo).");
    m.def(
        "types",
        []() {
            py::list names;
            for (const NamedType& t : builtin_types()) names.append(t.name);
            for (const TypeInfo* t : module_types())
                if (type_name(*t) == std::string(t->name)) names.append(std::string(t->name));
            return names;
        },
        "Type names that create_buffer, set_ray_type and variables take.");

    py::class_<Program, std::shared_ptr<Program>> program(m, "Program",
                                                          "A program of a compiled module.");
    program.def_property_readonly("name", [](const Program& p) { return p.name(); })
        .def_property_readonly("kind",
                               [](const Program& p) { return std::string(program_kind_name(p.kind())); })
        .def_property_readonly("module",
                               [](const Program& p) {
                                   return p.desc().module ? std::string(p.desc().module->name())
                                                          : std::string();
                               })
        .def_property_readonly("payload",
                               [](const Program& p) -> py::object {
                                   if (!p.desc().payload) return py::none();
                                   return py::str(type_name(*p.desc().payload));
                               })
        .def("__repr__", [](const Program& p) { return "<lucent." + p.describe() + ">"; });
    add_variable_access(program);
}

}  // namespace lucent::python
