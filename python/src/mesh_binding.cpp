// lucent.TriangleMesh: ray queries on numpy arrays (the shape trimesh users know), through
// the C++ package's scene::TriangleMesh (scene/triangle_mesh.h). The arrays are checked here,
// with the GIL held; the copies in and out and the launch run without it.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <span>
#include <string>

#include "array_args.h"
#include "bindings.h"
#include "scene/triangle_mesh.h"

namespace lucent::python {

namespace {

static_assert(sizeof(float3) == 3 * sizeof(float) && sizeof(float2) == 2 * sizeof(float) &&
                  sizeof(uint3) == 3 * sizeof(uint32_t),
              "(N, 3) and (N, 2) arrays are read as float3, float2 and uint3");

template <class T, class E>
std::span<T> as_span(E* data, size_t count) {
    return std::span<T>(reinterpret_cast<T*>(data), count);
}

/// What intersect() returns: one entry per ray.
struct RayHits {
    py::array_t<float> t;       // (R,) distance in units of the direction's length; inf: miss
    py::array_t<int32_t> prim;  // (R,) triangle index; -1: miss
    py::array_t<float> uv;      // (R, 2) barycentrics of vertices 1 and 2; 0 on a miss
    py::array_t<float> normal;  // (R, 3) unit geometric normal (winding order); 0 on a miss
};

class PyTriangleMesh {
  public:
    PyTriangleMesh(const py::handle& vertices, const py::handle& indices,
                   const std::string& backend, unsigned threads, int jit_check_sm) {
        const char* where = "TriangleMesh";
        py::ssize_t n = 0;
        py::array_t<float> v = float32_array(vertices, where, "vertices", {-1, 3}, "N", n);
        if (n == 0)
            throw py::value_error(std::string(where) +
                                  ": vertices is empty; a mesh needs at least three vertices");
        py::array_t<uint32_t> i = index_array(indices, where, "indices", size_t(n));
        ContextOptions options;
        options.backend = backend_kind(backend, "TriangleMesh: backend");
        options.threads = threads;
        options.jit_check_sm = jit_check_sm;
        const float* vp = v.data();
        const uint32_t* ip = i.data();
        const size_t triangles = size_t(i.shape(0));
        py::gil_scoped_release release;
        m_mesh = std::make_unique<scene::TriangleMesh>(as_span<const float3>(vp, size_t(n)),
                                                       as_span<const uint3>(ip, triangles),
                                                       std::move(options));
    }

    static std::unique_ptr<PyTriangleMesh> load(const std::string& path, const std::string& backend,
                                                unsigned threads, int jit_check_sm) {
        scene::MeshTriangles data;
        {
            py::gil_scoped_release release;
            data = scene::load_mesh_triangles(path);
        }
        py::array_t<float> v({py::ssize_t(data.positions.size()), py::ssize_t(3)},
                             reinterpret_cast<const float*>(data.positions.data()));
        py::array_t<uint32_t> i({py::ssize_t(data.indices.size()), py::ssize_t(3)},
                                reinterpret_cast<const uint32_t*>(data.indices.data()));
        return std::make_unique<PyTriangleMesh>(v, i, backend, threads, jit_check_sm);
    }

    RayHits intersect(const py::handle& origins, const py::handle& directions,
                      const py::handle& tmin, const py::handle& tmax) {
        Batch b = batch("TriangleMesh.intersect", origins, directions, tmin, tmax);
        const py::ssize_t r = py::ssize_t(b.rays.origins.size());
        RayHits hits{py::array_t<float>(r), py::array_t<int32_t>(r),
                     py::array_t<float>({r, py::ssize_t(2)}),
                     py::array_t<float>({r, py::ssize_t(3)})};
        const scene::MeshHits out{as_span<float>(hits.t.mutable_data(), size_t(r)),
                                  as_span<int32_t>(hits.prim.mutable_data(), size_t(r)),
                                  as_span<float2>(hits.uv.mutable_data(), size_t(r)),
                                  as_span<float3>(hits.normal.mutable_data(), size_t(r))};
        py::gil_scoped_release release;
        m_mesh->intersect(b.rays, out);
        return hits;
    }

    py::array_t<bool> occluded(const py::handle& origins, const py::handle& directions,
                               const py::handle& tmax, const py::handle& tmin) {
        Batch b = batch("TriangleMesh.occluded", origins, directions, tmin, tmax);
        py::array_t<bool> blocked(py::ssize_t(b.rays.origins.size()));
        static_assert(sizeof(bool) == 1, "numpy bools are one byte");
        const std::span<uint8_t> out =
            as_span<uint8_t>(blocked.mutable_data(), b.rays.origins.size());
        py::gil_scoped_release release;
        m_mesh->occluded(b.rays, out);
        return blocked;
    }

    void update(const py::handle& vertices, bool rebuild) {
        py::ssize_t n = 0;
        py::array_t<float> v =
            float32_array(vertices, "TriangleMesh.update", "vertices", {-1, 3}, "N", n);
        if (size_t(n) != m_mesh->vertex_count())
            throw py::value_error("TriangleMesh.update: vertices must be (" +
                                  std::to_string(m_mesh->vertex_count()) +
                                  ", 3), the mesh's vertex count; got " + describe_array(v) +
                                  " (make a new TriangleMesh for another vertex count)");
        const float* vp = v.data();
        py::gil_scoped_release release;
        m_mesh->update(as_span<const float3>(vp, size_t(n)), rebuild);
    }

    scene::TriangleMesh& mesh() { return *m_mesh; }

  private:
    /// The checked arrays of one query, kept alive while the launch reads them.
    struct Batch {
        py::array_t<float> origins, directions, tmin, tmax;
        scene::MeshRays rays;
    };

    Batch batch(const char* where, const py::handle& origins, const py::handle& directions,
                const py::handle& tmin, const py::handle& tmax) {
        Batch b;
        py::ssize_t r = 0, rd = 0;
        b.origins = float32_array(origins, where, "origins", {-1, 3}, "R", r);
        b.directions = float32_array(directions, where, "directions", {-1, 3}, "R", rd);
        if (rd != r)
            throw py::value_error(std::string(where) + ": directions must be (" +
                                  std::to_string(r) + ", 3) like origins; got " +
                                  describe_array(b.directions));
        if (uint64_t(r) > 0xffffffffull)
            throw py::value_error(std::string(where) + ": " + std::to_string(r) +
                                  " rays in one call; at most 4294967295 (split the batch)");
        b.tmin = interval_array(tmin, where, "tmin", r);
        b.tmax = interval_array(tmax, where, "tmax", r);
        b.rays.origins = as_span<const float3>(b.origins.data(), size_t(r));
        b.rays.directions = as_span<const float3>(b.directions.data(), size_t(r));
        b.rays.tmin = std::span<const float>(b.tmin.data(), size_t(b.tmin.size()));
        b.rays.tmax = std::span<const float>(b.tmax.data(), size_t(b.tmax.size()));
        return b;
    }

    std::unique_ptr<scene::TriangleMesh> m_mesh;
};

}  // namespace

void bind_triangle_mesh(py::module_& m) {
    py::class_<RayHits>(m, "RayHits",
                        "What TriangleMesh.intersect returns, one entry per ray: t (R,) float32 "
                        "(inf on a miss), prim (R,) int32 (-1 on a miss), uv (R, 2) float32 "
                        "barycentrics of vertices 1 and 2, normal (R, 3) float32 unit "
                        "geometric normal in the triangle's winding order (uv and normal are 0 "
                        "on a miss).")
        .def_readonly("t", &RayHits::t)
        .def_readonly("prim", &RayHits::prim)
        .def_readonly("uv", &RayHits::uv)
        .def_readonly("normal", &RayHits::normal)
        .def_property_readonly(
            "hit", [](const RayHits& h) { return py::array(h.prim.attr("__ge__")(0)); },
            "(R,) bool: the rays that hit")
        .def("__len__", [](const RayHits& h) { return h.t.size(); })
        .def("__repr__", [](const RayHits& h) {
            const py::ssize_t hits =
                py::int_(h.prim.attr("__ge__")(0).attr("sum")()).cast<py::ssize_t>();
            return "<lucent.RayHits: " + std::to_string(hits) + " of " +
                   std::to_string(h.t.size()) + " rays hit>";
        });

    py::class_<PyTriangleMesh>(m, "TriangleMesh",
                               "A triangle mesh to trace rays against, on any backend.")
        .def(py::init<const py::handle&, const py::handle&, const std::string&, unsigned, int>(),
             py::arg("vertices"), py::arg("indices"), py::arg("backend") = "auto",
             py::arg("threads") = 0u, py::arg("jit_check_sm") = 0,
             "vertices: (N, 3) float32 (float64 is converted); indices: (M, 3) uint32 (other "
             "integer dtypes are converted), each in [0, N). backend: 'auto', 'cpu' or 'cuda'. "
             "threads: CPU workers, 0 = one per core. jit_check_sm: with the CPU backend, also "
             "compile the GPU megakernel for this compute capability (e.g. 90), without a GPU.")
        .def_static("load", &PyTriangleMesh::load, py::arg("path"), py::arg("backend") = "auto",
                    py::arg("threads") = 0u, py::arg("jit_check_sm") = 0,
                    "A mesh from a file: .obj (positions and faces), .ply, .json, or a built-in "
                    "scene name ('cornell'), its meshes joined into one.")
        .def("intersect", &PyTriangleMesh::intersect, py::arg("origins"), py::arg("directions"),
             py::arg("tmin") = 0.0, py::arg("tmax") = py::float_(INFINITY),
             "The closest hit along each ray in (tmin, tmax): origins and directions (R, 3) "
             "float32; tmin and tmax a number or (R,). t is in units of the direction's "
             "length (directions need not be unit). Rays with a NaN or infinite origin or "
             "direction, a zero direction or a NaN bound are misses.")
        .def("occluded", &PyTriangleMesh::occluded, py::arg("origins"), py::arg("directions"),
             py::arg("tmax") = py::float_(INFINITY), py::arg("tmin") = 0.0,
             "(R,) bool: is any triangle on the ray in (tmin, tmax)? The shadow-ray query: it "
             "stops at the first triangle found. Rays that are not rays (see intersect) are "
             "not occluded.")
        .def("update", &PyTriangleMesh::update, py::arg("vertices"), py::arg("rebuild") = false,
             "New positions for the same (N, 3) vertices: the BVH is refitted at the next "
             "query, or rebuilt with rebuild=True (better after large motions).")
        .def_property_readonly("vertex_count",
                               [](PyTriangleMesh& m) { return m.mesh().vertex_count(); })
        .def_property_readonly("triangle_count",
                               [](PyTriangleMesh& m) { return m.mesh().triangle_count(); })
        .def_property_readonly(
            "backend", [](PyTriangleMesh& m) { return m.mesh().backend_name(); },
            "The backend that runs the queries: 'cpu (2 threads)', 'cuda (...)'")
        .def_property_readonly(
            "last_launch", [](PyTriangleMesh& m) { return m.mesh().last_launch(); },
            "The LaunchReport of the most recent query (timings; jit_ms with jit_check_sm)")
        .def("__repr__", [](PyTriangleMesh& m) {
            return "<lucent.TriangleMesh: " + std::to_string(m.mesh().vertex_count()) +
                   " vertices, " + std::to_string(m.mesh().triangle_count()) + " triangles on " +
                   m.mesh().backend_name() + ">";
        });
}

}  // namespace lucent::python
