// PLY meshes (Turk 1994): ASCII and binary (little or big endian); vertex x, y, z (and nx,
// ny, nz; u, v or s, t when present), faces as index lists fanned into triangles. Debian
// has no PLY library, so this small reader is ours. Errors name the file and the header
// line, or the element of the body, at fault.
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/scene.h"

namespace lucent::scene {

namespace {

/// A number read from a PLY for a message: "1.9", "nan", "1e+300" (never converted to an
/// integer type, which NaN and huge values would make undefined).
std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
}

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct Property {
    std::string name;
    std::string type;        // scalar type, or the item type of a list
    std::string count_type;  // lists only
    bool list = false;
};

struct Element {
    std::string name;
    size_t count = 0;
    std::vector<Property> properties;
};

size_t type_size(const std::string& t) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
        t == "float32")
        return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
}

class Reader {
  public:
    Reader(std::string path, std::istream& in, Format format)
        : m_path(std::move(path)), m_in(in), m_format(format) {}

    [[noreturn]] void fail(const std::string& message) const {
        throw Error(m_path + ": " + message);
    }

    /// One value of `type` as a double (ASCII: the next token).
    double value(const std::string& type, const std::string& where) {
        if (m_format == Format::kAscii) {
            std::string token;
            if (!(m_in >> token)) fail(where + ": the file ends early");
            char* end = nullptr;
            double v = std::strtod(token.c_str(), &end);
            if (end == token.c_str() || *end) fail(where + ": '" + token + "' is not a number");
            return v;
        }
        unsigned char b[8];
        const size_t n = type_size(type);
        if (!m_in.read(reinterpret_cast<char*>(b), std::streamsize(n)))
            fail(where + ": the file ends early");
        if ((m_format == Format::kBinaryBig) == (std::endian::native == std::endian::little))
            for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
        auto as = [&](auto zero) {
            decltype(zero) v;
            std::memcpy(&v, b, sizeof v);
            return double(v);
        };
        if (type == "char" || type == "int8") return as(int8_t());
        if (type == "uchar" || type == "uint8") return as(uint8_t());
        if (type == "short" || type == "int16") return as(int16_t());
        if (type == "ushort" || type == "uint16") return as(uint16_t());
        if (type == "int" || type == "int32") return as(int32_t());
        if (type == "uint" || type == "uint32") return as(uint32_t());
        if (type == "float" || type == "float32") return as(float());
        return as(double());
    }

  private:
    std::string m_path;
    std::istream& m_in;
    Format m_format;
};

/// The header's element counts against the bytes after it: each item of an element takes at
/// least its scalars' and list counts' bytes in a binary file, and a character and a
/// separator per property in an ASCII one. A header that claims more than the file holds
/// (a damaged or hostile file) is refused before anything is allocated or read, and an
/// element without properties may have no items (they would take no bytes at all).
void check_declared_counts(const std::string& path, const std::vector<Element>& elements,
                           Format format, uint64_t bytes_after_header) {
    long double needed = 0;
    for (const Element& e : elements) {
        if (e.count > 0 && e.properties.empty())
            throw Error(path + ": element '" + e.name + "' declares " + std::to_string(e.count) +
                        " items but no properties; a PLY element needs at least one property");
        uint64_t per_item = 0;
        for (const Property& p : e.properties)
            per_item += format == Format::kAscii ? 2 : type_size(p.list ? p.count_type : p.type);
        needed += static_cast<long double>(per_item) * e.count;
    }
    if (needed > static_cast<long double>(bytes_after_header))
        throw Error(path + ": the header declares elements that need at least " +
                    std::to_string(static_cast<unsigned long long>(needed)) + " bytes, but " +
                    std::to_string(bytes_after_header) +
                    " follow it; the file is truncated or its element counts are wrong");
}

}  // namespace

Mesh load_ply_mesh(const std::string& path) {
    require_regular_file(path, "PLY file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ":0: cannot open the PLY file (check the path)");
    auto fail_at = [&](size_t line, const std::string& m) -> void {
        throw Error(path + ":" + std::to_string(line) + ": " + m);
    };
    std::string line;
    size_t line_no = 0;
    std::getline(in, line), ++line_no;
    if (line != "ply" && line != "ply\r")
        fail_at(1, "not a PLY file (the first line must be 'ply')");
    Format format = Format::kAscii;
    bool have_format = false;
    std::vector<Element> elements;
    for (;;) {
        if (!std::getline(in, line)) fail_at(line_no, "the header has no end_header");
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "end_header") break;
        if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "format") {
            std::string name, version;
            words >> name >> version;
            if (name == "ascii")
                format = Format::kAscii;
            else if (name == "binary_little_endian")
                format = Format::kBinaryLittle;
            else if (name == "binary_big_endian")
                format = Format::kBinaryBig;
            else
                fail_at(line_no, "unknown format '" + name + "'");
            have_format = true;
        } else if (keyword == "element") {
            Element e;
            long long count = -1;
            words >> e.name >> count;
            if (e.name.empty() || count < 0 || count > (1ll << 31))
                fail_at(line_no, "expected 'element NAME COUNT' with a count below 2^31");
            e.count = size_t(count);
            elements.push_back(e);
        } else if (keyword == "property") {
            if (elements.empty()) fail_at(line_no, "a property before any element");
            Property p;
            std::string type;
            words >> type;
            if (type == "list") {
                p.list = true;
                words >> p.count_type >> p.type >> p.name;
                if (!type_size(p.count_type) || !type_size(p.type))
                    fail_at(line_no, "unknown list types '" + p.count_type + " " + p.type + "'");
            } else {
                p.type = type;
                words >> p.name;
                if (!type_size(p.type)) fail_at(line_no, "unknown property type '" + type + "'");
            }
            if (p.name.empty()) fail_at(line_no, "a property needs a name");
            elements.back().properties.push_back(p);
        } else {
            fail_at(line_no, "unknown header line '" + keyword + "'");
        }
    }
    if (!have_format) fail_at(line_no, "the header has no format line");
    check_declared_counts(path, elements, format, file_size(path) - uint64_t(in.tellg()));

    Reader reader(path, in, format);
    Mesh mesh;
    mesh.name = path;
    bool vertices_read = false;
    for (const Element& e : elements) {
        const bool vertices = e.name == "vertex", faces = e.name == "face";
        if (faces && e.count > 0 && !vertices_read)
            reader.fail("the face element comes before the vertex element; write vertices first");
        vertices_read = vertices_read || vertices;
        int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, u = -1, v = -1;
        for (size_t i = 0; i < e.properties.size(); ++i) {
            const std::string& n = e.properties[i].name;
            int k = int(i);
            if (n == "x")
                x = k;
            else if (n == "y")
                y = k;
            else if (n == "z")
                z = k;
            else if (n == "nx")
                nx = k;
            else if (n == "ny")
                ny = k;
            else if (n == "nz")
                nz = k;
            else if (n == "u" || n == "s" || n == "texture_u")
                u = k;
            else if (n == "v" || n == "t" || n == "texture_v")
                v = k;
        }
        if (vertices && (x < 0 || y < 0 || z < 0))
            reader.fail("the vertex element has no x, y and z");
        const bool normals = nx >= 0 && ny >= 0 && nz >= 0, uvs = u >= 0 && v >= 0;
        for (size_t item = 0; item < e.count; ++item) {
            const std::string where = "element '" + e.name + "' " + std::to_string(item);
            double scalar[16] = {};
            std::vector<double> list;
            for (size_t pi = 0; pi < e.properties.size(); ++pi) {
                const Property& p = e.properties[pi];
                if (!p.list) {
                    double value = reader.value(p.type, where);
                    if (pi < 16) scalar[pi] = value;
                    continue;
                }
                double count = reader.value(p.count_type, where);
                if (!(count >= 0 && count <= 1024 && count == std::floor(count)))
                    reader.fail(where + ": a list of " + number_text(count) +
                                " items (a whole number, at most 1024)");
                list.resize(size_t(count));
                for (double& item_value : list) item_value = reader.value(p.type, where);
                if (faces && p.name.rfind("vertex_ind", 0) == 0) {
                    for (size_t k = 0; k < list.size(); ++k) {
                        if (list[k] != std::floor(list[k]))  // NaN too: never equal
                            reader.fail(where + ": vertex index " + number_text(list[k]) +
                                        " is not a whole number");
                        if (!(list[k] >= 0 && list[k] < double(mesh.positions.size())))
                            reader.fail(where + ": vertex index " + number_text(list[k]) +
                                        " out of range (there are " +
                                        std::to_string(mesh.positions.size()) + " vertices)");
                    }
                    for (size_t k = 1; k + 1 < list.size(); ++k)
                        mesh.indices.push_back(
                            uint3{unsigned(list[0]), unsigned(list[k]), unsigned(list[k + 1])});
                }
            }
            if (vertices) {
                if (x >= 16 || y >= 16 || z >= 16)
                    reader.fail("x, y and z must be among the first 16 vertex properties");
                float3 p = make_float3(float(scalar[x]), float(scalar[y]), float(scalar[z]));
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                    reader.fail(where + ": a coordinate is not finite");
                mesh.positions.push_back(p);
                if (normals && nx < 16 && ny < 16 && nz < 16)
                    mesh.normals.push_back(
                        make_float3(float(scalar[nx]), float(scalar[ny]), float(scalar[nz])));
                if (uvs && u < 16 && v < 16)
                    mesh.uvs.push_back(make_float2(float(scalar[u]), float(scalar[v])));
            }
        }
    }
    if (mesh.indices.empty())
        throw Error(path + ": the PLY file has no faces (no triangles to render)");
    if (mesh.normals.size() != mesh.positions.size()) mesh.normals.clear();
    if (mesh.uvs.size() != mesh.positions.size()) mesh.uvs.clear();
    mesh.materials.assign(mesh.indices.size(), 0u);
    return mesh;
}

}  // namespace lucent::scene
