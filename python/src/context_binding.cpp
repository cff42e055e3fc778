// lucent.Context from Python: the backend, entry points and ray types, program modules,
// object creation and launch (lucent/context.h), and the LaunchReport a launch leaves.
// A launch runs without the GIL; a Context and what it creates are used from one Python
// thread at a time, as in C++.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.h"

namespace lucent::python {

std::vector<DeviceSpec> device_list(const py::object& devices) {
    if (devices.is_none()) return {};
    std::string list;
    if (py::isinstance<py::str>(devices)) {
        list = devices.cast<std::string>();
    } else {
        for (const py::handle& d : devices)
            list += (list.empty() ? "" : ",") + py::str(d).cast<std::string>();
    }
    return parse_device_list(list);
}

namespace {

/// The payload type of a ray type: a type name, or a Program whose payload it takes.
const TypeInfo& payload_type(const py::handle& payload) {
    if (py::isinstance<Program>(payload)) {
        const Program& p = payload.cast<const Program&>();
        if (!p.desc().payload)
            throw py::value_error("set_ray_type: payload " + p.describe() +
                                  " takes no payload; give a miss, closest-hit or any-hit "
                                  "program, or the payload's type name");
        return *p.desc().payload;
    }
    if (py::isinstance<py::str>(payload))
        return type_by_name(payload.cast<std::string>(), "set_ray_type: payload");
    throw py::type_error("set_ray_type: payload must be a type name or a Program; got " +
                         py::repr(payload).cast<std::string>());
}

RegisterVariants register_variants(const std::string& name) {
    if (name == "background") return RegisterVariants::kBackground;
    if (name == "with_kernel") return RegisterVariants::kWithKernel;
    if (name == "off") return RegisterVariants::kOff;
    throw py::value_error("Context: register_variants: expected 'background', 'with_kernel' or "
                          "'off'; got '" + name + "'");
}

TreeUpgrades tree_upgrades(const std::string& name) {
    if (name == "background") return TreeUpgrades::kBackground;
    if (name == "with_build") return TreeUpgrades::kWithBuild;
    if (name == "off") return TreeUpgrades::kOff;
    throw py::value_error(
        "Context: tree_upgrades: expected 'background', 'with_build' or "
        "'off'; got '" +
        name + "'");
}

ContextOptions context_options(const std::string& backend, unsigned threads, int jit_check_sm,
                               const py::object& devices, const py::object& ranks,
                               const std::string& variants, const std::string& upgrades) {
    ContextOptions options;
    options.register_variants = register_variants(variants);
    options.tree_upgrades = tree_upgrades(upgrades);
    options.ranks = ranks_argument(ranks, "Context: ranks");
    options.backend = backend_kind(backend, "Context: backend");
    options.threads = threads;
    options.jit_check_sm = jit_check_sm;
    options.devices = device_list(devices);
    return options;
}

}  // namespace

void bind_context(py::module_& m) {
    py::class_<LaunchReport> report(m, "LaunchReport",
                                    "Exceptions and timings of a launch (milliseconds).");
    py::class_<LaunchReport::DeviceShare>(report, "DeviceShare",
                                          "What one device of a multi-device launch ran.")
        .def_readonly("device", &LaunchReport::DeviceShare::device, "'cpu' or 'cuda:0'")
        .def_readonly("indices", &LaunchReport::DeviceShare::indices, "launch indices it ran")
        .def_readonly("pieces", &LaunchReport::DeviceShare::pieces, "pieces it took from the queue")
        .def_readonly("busy_ms", &LaunchReport::DeviceShare::busy_ms,
                      "from its first piece's start to its last piece's end")
        .def("__repr__", [](const LaunchReport::DeviceShare& d) {
            return "<lucent.LaunchReport.DeviceShare " + d.device + ": " +
                   std::to_string(d.indices) + " indices in " + std::to_string(d.pieces) +
                   " pieces>";
        });
    py::class_<LaunchReport::RankShare>(report, "RankShare",
                                        "What one rank of a launch spread over ranks ran.")
        .def_readonly("indices", &LaunchReport::RankShare::indices, "launch indices it ran")
        .def_readonly("pieces", &LaunchReport::RankShare::pieces,
                      "pieces it took from the shared counter")
        .def_readonly("busy_ms", &LaunchReport::RankShare::busy_ms,
                      "its devices' run, from the launch's start on that rank")
        .def("__repr__", [](const LaunchReport::RankShare& r) {
            return "<lucent.LaunchReport.RankShare: " + std::to_string(r.indices) + " indices in " +
                   std::to_string(r.pieces) + " pieces>";
        });
    report.def_readonly("compile_ms", &LaunchReport::compile_ms)
        .def_readonly("accel_ms", &LaunchReport::accel_ms)
        .def_readonly("launch_ms", &LaunchReport::launch_ms)
        .def_readonly("recompiled", &LaunchReport::recompiled)
        .def_readonly("jit_ms", &LaunchReport::jit_ms)
        .def_readonly("jit_cached", &LaunchReport::jit_cached)
        .def_readonly("kernel_ms", &LaunchReport::kernel_ms)
        .def_readonly("launch_shape_trial", &LaunchReport::launch_shape_trial)
        .def_readonly("registers_capped", &LaunchReport::registers_capped)
        .def_readonly("register_cap", &LaunchReport::register_cap)
        .def_readonly("trace_inlined", &LaunchReport::trace_inlined)
        .def_readonly("lanes_refilled", &LaunchReport::lanes_refilled)
        .def_readonly("trees_upgraded", &LaunchReport::trees_upgraded,
                      "CUDA: triangle trees this launch traced for the first time in place of "
                      "the GPU-built trees they upgraded (Context(tree_upgrades=...)).")
        .def_readonly("exchange_ms", &LaunchReport::exchange_ms)
        .def_readonly("devices", &LaunchReport::devices,
                      "Multi-device launches: a DeviceShare per device, in the Context's "
                      "device order (empty on one device).")
        .def_readonly("ranks", &LaunchReport::ranks,
                      "Launches spread over ranks (Context(ranks=...)): a RankShare per rank, "
                      "in rank order (empty when the launch ran whole on every rank).")
        .def_readonly("gather_ms", &LaunchReport::gather_ms,
                      "Launches spread over ranks: the gather of the other ranks' pieces "
                      "(within launch_ms).")
        .def_property_readonly("exception_count", &LaunchReport::exception_count)
        .def_property_readonly(
            "exceptions",
            [](const LaunchReport& r) {
                py::dict d;
                for (const auto& [code, e] : r.exceptions)
                    d[py::str(exception_name(code))] = py::make_tuple(
                        e.count, py::make_tuple(e.first_index.x, e.first_index.y, e.first_index.z));
                return d;
            },
            "{name: (count, first launch index)}")
        .def("summary", &LaunchReport::summary)
        .def("__repr__", [](const LaunchReport& r) {
            return "<lucent.LaunchReport: launch " + std::to_string(r.launch_ms) + " ms, " +
                   std::to_string(r.exception_count()) + " exceptions>";
        });

    py::class_<Context, std::shared_ptr<Context>> ctx(
        m, "Context", "Owns the entry points, ray types and objects of a scene, and launches.");
    ctx.def(py::init([](const std::string& backend, unsigned threads, int jit_check_sm,
                        const py::object& devices, const py::object& ranks,
                        const std::string& variants, const std::string& upgrades) {
                ContextOptions options = context_options(backend, threads, jit_check_sm, devices,
                                                         ranks, variants, upgrades);
                py::gil_scoped_release release;  // a CUDA context takes a while to start
                return std::make_shared<Context>(std::move(options));
            }),
            py::arg("backend") = "auto", py::arg("threads") = 0u, py::arg("jit_check_sm") = 0,
            py::arg("devices") = py::none(), py::arg("ranks") = py::none(),
            py::arg("register_variants") = "background", py::arg("tree_upgrades") = "background",
            "backend: 'auto', 'cpu' or 'cuda'; threads: CPU workers (0: one per core); "
            "jit_check_sm: with the CPU backend, also compile the GPU megakernel for this "
            "compute capability (90: sm_90) at each compile, without a GPU; devices: '0,1', "
            "'cpu,0', 'all' or a list, to spread launches over several devices; ranks: a "
            "lucent.Ranks (lucent.Ranks.world() under mpirun) to spread them over the "
            "processes of an MPI job, each on its own devices (every rank runs the same "
            "script; docs/distributed.md); register_variants: CUDA, for kernels of more than "
            "64 registers a thread, a variant capped at 64 that the launch-shape tuning "
            "times beside the others: 'background' (compiled after the first launch), "
            "'with_kernel' (compiled before it: reproducible timings) or 'off'; "
            "tree_upgrades: CUDA, for groups of triangles the GPU builds (builder 'auto'), the "
            "host's tree with spatial splits in place of the GPU's: 'background' (built on "
            "another thread, used from the first launch after it is ready), 'with_build' "
            "(built before the first launch: reproducible timings) or 'off'.")
        .def_property_readonly("backend", &Context::backend_name)
        .def_property_readonly("backend_notice", &Context::backend_notice)
        .def_property_readonly("device_count", &Context::device_count)
        .def_property(
            "devices",
            [](const Context& c) {
                std::vector<std::string> names;
                for (const DeviceSpec& d : c.devices()) names.push_back(device_spec_name(d));
                return names;
            },
            [](Context& c, const py::object& devices) {
                std::vector<DeviceSpec> list = device_list(devices);
                py::gil_scoped_release release;  // a CUDA context takes a while to start
                c.set_devices(std::move(list));
            },
            "The devices launches run on, as names ('cpu', 'cuda:0'). Set it to move later "
            "launches onto other devices ('0,1', 'cpu,0', 'all', a list, or None for the "
            "backend's one device): what launches wrote is kept, the scene is compiled again.")
        .def_property("random_seed", &Context::random_seed, &Context::set_random_seed)
        .def_property("entry_point_count", &Context::entry_point_count,
                      &Context::set_entry_point_count)
        .def("set_ray_generation_program", &Context::set_ray_generation_program, py::arg("entry"),
             py::arg("program"))
        .def("ray_generation_program", &Context::ray_generation_program)
        .def("set_exception_program", &Context::set_exception_program, py::arg("entry"),
             py::arg("program"))
        .def("exception_program", &Context::exception_program)
        .def(
            "set_ray_type",
            [](Context& c, unsigned index, std::string name, const py::handle& payload,
               bool expects_closest_hit, std::vector<std::shared_ptr<Node>> roots) {
                c.set_ray_type(index, RayTypeDesc{std::move(name), &payload_type(payload),
                                                  expects_closest_hit, std::move(roots)});
            },
            py::arg("index"), py::arg("name"), py::arg("payload"),
            py::arg("expects_closest_hit") = true,
            py::arg("roots") = std::vector<std::shared_ptr<Node>>{},
            "Declares ray type `index`; payload: the payload's type name, or a program that "
            "takes it (its miss or closest hit).")
        .def_property_readonly("ray_type_count", &Context::ray_type_count)
        .def("ray_type_name",
             [](const Context& c, unsigned index) { return c.ray_type(index).name; })
        .def("set_miss_program", &Context::set_miss_program, py::arg("ray_type"),
             py::arg("program"))
        .def("miss_program", &Context::miss_program)
        .def_property("max_recursion_depth", &Context::max_recursion_depth,
                      &Context::set_max_recursion_depth)
        .def("set_exception_enabled", &Context::set_exception_enabled, py::arg("code"),
             py::arg("enabled"), "An exception code, or lucent.ALL_EXCEPTIONS.")
        .def("exception_enabled", &Context::exception_enabled)
        .def_property("print_enabled", &Context::print_enabled, &Context::set_print_enabled)
        .def(
            "add_module",
            [](Context& c, const std::optional<std::string>& module,
               const std::optional<std::string>& file, const std::string& name,
               const std::vector<std::string>& include_dirs) -> const ModuleInfo& {
                if (module && file)
                    throw py::value_error("Context.add_module: give a module (its name or its "
                                          "C++ text) or file=, not both");
                if (!module && !file)
                    throw py::value_error("Context.add_module: give a module's name "
                                          "(lucent.modules()), its C++ text, or file=path");
                // A module's text declares LUCENT_MODULE; a module's name has no spaces.
                const bool is_text = module && (module->find("LUCENT_MODULE") != std::string::npos ||
                                                module->find('\n') != std::string::npos);
                if (module && !is_text) return c.add_module(*module);
                ModuleSource source = file ? ModuleSource::from_file(*file, include_dirs)
                                           : ModuleSource::from_text(name, *module, include_dirs);
                py::gil_scoped_release release;  // a cold compile takes seconds
                return c.add_module(std::move(source));
            },
            py::arg("module") = py::none(), py::kw_only(), py::arg("file") = py::none(),
            py::arg("name") = "python_module.h",
            py::arg("include_dirs") = std::vector<std::string>{},
            py::return_value_policy::reference,
            "Makes a program module available to create_program: a module compiled into this "
            "extension by its name (lucent.modules()), or a module's C++ text (a string with "
            "its LUCENT_MODULE) or header (file=), which is compiled now with the system's C++ "
            "compiler for the host (cached on disk) and with NVRTC for the GPU. `name` names "
            "the text in the compiler's messages; quoted includes are looked up beside it and "
            "in include_dirs.")
        .def(
            "create_program",
            [](Context& c, const std::string& name, const std::optional<std::string>& module) {
                if (!module) return c.create_program(name);
                return c.create_program(c.add_module(*module), name);
            },
            py::arg("name"), py::arg("module") = py::none(),
            "The program `name` of an added module (or of `module`, which is added).")
        .def(
            "create_buffer",
            [](Context& c, const std::string& type, const std::string& element,
               const py::handle& size) {
                const std::vector<unsigned> s = parse_buffer_size(size);
                const TypeInfo& e = type_by_name(element, "create_buffer: element");
                return c.create_buffer(buffer_type_from(type), e, s[0], s.size() > 1 ? s[1] : 0,
                                       s.size() > 2 ? s[2] : 0);
            },
            py::arg("type"), py::arg("element"), py::arg("size"),
            "type: 'input', 'output' or 'input_output'; element: a type name ('float3', "
            "'uint', ...: lucent.types()); size: width, (width, height) or (width, height, "
            "depth).")
        .def("create_texture_sampler", &Context::create_texture_sampler)
        .def(
            "create_acceleration",
            [](Context& c, const std::string& builder) {
                return c.create_acceleration(builder_from_name(builder));
            },
            py::arg("builder") = "auto")
        .def("create_group", &Context::create_group)
        .def("create_geometry_group", &Context::create_geometry_group)
        .def("create_transform", &Context::create_transform)
        .def("create_selector", &Context::create_selector)
        .def("create_geometry_instance", &Context::create_geometry_instance)
        .def("create_geometry", &Context::create_geometry)
        .def("create_geometry_triangles", &Context::create_geometry_triangles)
        .def("create_geometry_spheres", &Context::create_geometry_spheres)
        .def("create_geometry_curves", &Context::create_geometry_curves)
        .def("create_material", &Context::create_material)
        .def("validate", &Context::validate, py::call_guard<py::gil_scoped_release>(),
             "Checks everything a launch would, without launching; raises lucent.Error.")
        .def(
            "launch",
            [](Context& c, unsigned entry, unsigned width, unsigned height, unsigned depth) {
                {
                    py::gil_scoped_release release;
                    if (depth)
                        c.launch(entry, width, height ? height : 1, depth);
                    else if (height)
                        c.launch(entry, width, height);
                    else
                        c.launch(entry, width);
                }
                return c.last_launch();
            },
            py::arg("entry"), py::arg("width"), py::arg("height") = 0u, py::arg("depth") = 0u,
            "Runs entry point `entry` over width (x height (x depth)) launch indices; "
            "returns the LaunchReport.")
        .def_property_readonly("last_launch", &Context::last_launch)
        .def("__repr__",
             [](const Context& c) { return "<lucent.Context on " + c.backend_name() + ">"; });
    add_variable_access(ctx);
    m.attr("ALL_EXCEPTIONS") = kAllExceptions;
}

}  // namespace lucent::python
