// PLY meshes (Turk 1994): ASCII and binary (little or big endian); vertex x, y, z (and nx,
// ny, nz; u, v or s, t when present), faces as index lists fanned into triangles. Debian
// has no PLY library, so this small reader is ours. Errors name the file and the header
// line, or the element of the body, at fault.
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/load_progress.h"
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

/// A property's scalar type, resolved once from its name (not compared per value).
enum class Type : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct Property {
    std::string name;
    std::string type;        // scalar type, or the item type of a list
    std::string count_type;  // lists only
    bool list = false;
    Type value_type{}, length_type{};  // resolved from type and count_type
    size_t value_bytes = 0, length_bytes = 0;
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

Type type_of(const std::string& t) {
    if (t == "char" || t == "int8") return Type::kInt8;
    if (t == "uchar" || t == "uint8") return Type::kUint8;
    if (t == "short" || t == "int16") return Type::kInt16;
    if (t == "ushort" || t == "uint16") return Type::kUint16;
    if (t == "int" || t == "int32") return Type::kInt32;
    if (t == "uint" || t == "uint32") return Type::kUint32;
    if (t == "float" || t == "float32") return Type::kFloat32;
    return Type::kFloat64;
}

/// The body of a PLY, read from the end of its header in 1 MiB blocks (an std::istream
/// read per value, and a message string built per item, held a 1 GB file to 18 MB/s),
/// reporting the bytes read to `progress`. Errors name the element and item being read,
/// which the caller sets with at().
class Reader {
  public:
    Reader(std::string path, uint64_t body_start, Format format, const LoadProgress& progress)
        : m_path(std::move(path)),
          m_format(format),
          m_progress(progress),
          m_block(size_t(1) << 20),
          m_stage("reading " + std::filesystem::path(m_path).filename().string()) {
        m_file = std::fopen(m_path.c_str(), "rb");
        if (!m_file || std::fseek(m_file, long(body_start), SEEK_SET) != 0)
            fail_plain("cannot open the PLY file (check the path)");
        m_total = file_size(m_path);
        m_read = body_start;
    }
    ~Reader() {
        if (m_file) std::fclose(m_file);
    }
    Reader(const Reader&) = delete;
    Reader& operator=(const Reader&) = delete;

    [[noreturn]] void fail_plain(const std::string& message) const {
        throw Error(m_path + ": " + message);
    }
    /// "path: element 'face' 12: message".
    [[noreturn]] void fail(const std::string& message) const {
        fail_plain("element '" + *m_element + "' " + std::to_string(m_item) + ": " + message);
    }
    /// The element and item the next values belong to, for messages.
    void at(const std::string& element, size_t item) {
        m_element = &element;
        m_item = item;
    }

    /// One value of `type` as a double (ASCII: the next token).
    double value(Type type, size_t bytes) {
        if (m_format == Format::kAscii) return ascii_value();
        unsigned char b[8];
        for (size_t i = 0; i < bytes; ++i) {
            const int c = next_byte();
            if (c < 0) fail("the file ends early");
            b[i] = (unsigned char)c;
        }
        if ((m_format == Format::kBinaryBig) == (std::endian::native == std::endian::little))
            for (size_t i = 0; i < bytes / 2; ++i) std::swap(b[i], b[bytes - 1 - i]);
        auto as = [&](auto zero) {
            decltype(zero) v;
            std::memcpy(&v, b, sizeof v);
            return double(v);
        };
        switch (type) {
            case Type::kInt8: return as(int8_t());
            case Type::kUint8: return as(uint8_t());
            case Type::kInt16: return as(int16_t());
            case Type::kUint16: return as(uint16_t());
            case Type::kInt32: return as(int32_t());
            case Type::kUint32: return as(uint32_t());
            case Type::kFloat32: return as(float());
            case Type::kFloat64: break;
        }
        return as(double());
    }

  private:
    int next_byte() {
        if (m_pos == m_end) {
            m_pos = 0;
            m_end = std::fread(m_block.data(), 1, m_block.size(), m_file);
            m_read += m_end;
            if (m_progress) m_progress(m_stage, m_read, std::max(m_read, m_total));
            if (m_end == 0) return -1;
        }
        return (unsigned char)m_block[m_pos++];
    }

    /// An ASCII number: a token of at most 64 characters (a NUL byte or a longer token is
    /// a damaged file, which would otherwise be read as one token of gigabytes).
    double ascii_value() {
        int c = next_byte();
        while (c == ' ' || c == '\t' || c == '\n' || c == '\r') c = next_byte();
        if (c < 0) fail("the file ends early");
        char token[72];
        size_t n = 0;
        for (; c > 0 && c != ' ' && c != '\t' && c != '\n' && c != '\r'; c = next_byte()) {
            if (n == 64) fail("a value longer than 64 characters; the file is damaged");
            token[n++] = char(c);
        }
        if (c == 0) fail("a NUL byte in an ASCII PLY: the file holds binary data, not text");
        token[n] = 0;
        char* end = nullptr;
        const double v = std::strtod(token, &end);
        if (end == token || *end) fail("'" + std::string(token) + "' is not a number");
        return v;
    }

    std::string m_path;
    Format m_format;
    const LoadProgress& m_progress;
    std::vector<char> m_block;
    std::string m_stage;
    std::FILE* m_file = nullptr;
    size_t m_pos = 0, m_end = 0;
    uint64_t m_read = 0, m_total = 0;
    const std::string* m_element = nullptr;
    size_t m_item = 0;
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

/// A header line of at most 4096 bytes: a file that is not a PLY (a sparse file, binary
/// data) would otherwise be read as one line of gigabytes. False at the end of the file.
bool header_line(std::istream& in, std::string& line, const std::string& path, size_t line_no) {
    line.clear();
    for (int c; (c = in.get()) != std::char_traits<char>::eof();) {
        if (c == '\n') return true;
        if (c == 0 || line.size() == 4096)
            throw Error(path + ":" + std::to_string(line_no) + ": " +
                        (c == 0 ? "a NUL byte" : "a line over 4096 bytes") +
                        " in the header: not a PLY file, or a damaged one");
        line.push_back(char(c));
    }
    return !line.empty();
}

}  // namespace

Mesh load_ply_mesh(const std::string& path, const LoadProgress& progress) {
    require_regular_file(path, "PLY file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ":0: cannot open the PLY file (check the path)");
    auto fail_at = [&](size_t line, const std::string& m) -> void {
        throw Error(path + ":" + std::to_string(line) + ": " + m);
    };
    std::string line;
    size_t line_no = 0;
    header_line(in, line, path, 1), ++line_no;
    if (line != "ply" && line != "ply\r")
        fail_at(1, "not a PLY file (the first line must be 'ply')");
    Format format = Format::kAscii;
    bool have_format = false;
    std::vector<Element> elements;
    for (;;) {
        if (!header_line(in, line, path, line_no + 1))
            fail_at(line_no, "the header has no end_header");
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
            p.value_type = type_of(p.type);
            p.value_bytes = type_size(p.type);
            if (p.list) {
                p.length_type = type_of(p.count_type);
                p.length_bytes = type_size(p.count_type);
            }
            elements.back().properties.push_back(p);
        } else {
            fail_at(line_no, "unknown header line '" + keyword + "'");
        }
    }
    if (!have_format) fail_at(line_no, "the header has no format line");
    const uint64_t body_start = uint64_t(in.tellg());
    check_declared_counts(path, elements, format, file_size(path) - body_start);
    in.close();

    Reader reader(path, body_start, format, progress);
    Mesh mesh;
    mesh.name = path;
    bool vertices_read = false;
    for (const Element& e : elements) {
        const bool vertices = e.name == "vertex", faces = e.name == "face";
        if (faces && e.count > 0 && !vertices_read)
            reader.fail_plain("the face element comes before the vertex element; write vertices first");
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
            reader.fail_plain("the vertex element has no x, y and z");
        const bool normals = nx >= 0 && ny >= 0 && nz >= 0, uvs = u >= 0 && v >= 0;
        std::vector<double> list;  // one list's values, reused: no allocation per face
        if (vertices) mesh.positions.reserve(e.count);
        for (size_t item = 0; item < e.count; ++item) {
            reader.at(e.name, item);
            double scalar[16] = {};
            for (size_t pi = 0; pi < e.properties.size(); ++pi) {
                const Property& p = e.properties[pi];
                if (!p.list) {
                    const double value = reader.value(p.value_type, p.value_bytes);
                    if (pi < 16) scalar[pi] = value;
                    continue;
                }
                const double count = reader.value(p.length_type, p.length_bytes);
                if (!(count >= 0 && count <= 1024 && count == std::floor(count)))
                    reader.fail("a list of " + number_text(count) +
                                " items (a whole number, at most 1024)");
                list.resize(size_t(count));
                for (double& item_value : list)
                    item_value = reader.value(p.value_type, p.value_bytes);
                if (faces && p.name.rfind("vertex_ind", 0) == 0) {
                    for (size_t k = 0; k < list.size(); ++k) {
                        if (list[k] != std::floor(list[k]))  // NaN too: never equal
                            reader.fail("vertex index " + number_text(list[k]) +
                                        " is not a whole number");
                        if (!(list[k] >= 0 && list[k] < double(mesh.positions.size())))
                            reader.fail("vertex index " + number_text(list[k]) +
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
                    reader.fail_plain("x, y and z must be among the first 16 vertex properties");
                float3 p = make_float3(float(scalar[x]), float(scalar[y]), float(scalar[z]));
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                    reader.fail("a coordinate is not finite");
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
