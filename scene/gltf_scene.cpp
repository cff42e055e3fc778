// A Scene from a glTF 2.0 file (.gltf with its buffers and images, or .glb) through
// tinygltf (Debian's libtinygltf-dev). tinygltf parses the JSON, the GLB container, data
// URIs and external files; everything read from the model afterwards (indices into other
// arrays, accessor ranges within their buffers) is checked here, because tinygltf 2.7 does
// not, and a bad index would otherwise read out of bounds. Errors name the file and the
// JSON path ("meshes[2].primitives[0].attributes.POSITION").
//
// The node hierarchy is flattened into instances: each node that has a mesh becomes one
// Instance of that mesh with the node's world matrix, and a mesh used by several nodes is
// one Scene mesh (one GeometryGroup and BVH in the samples' graph, samples/scene_setup.h).
#include <stb_image.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/scene.h"
#include "scene/texture_image.h"

namespace lucent::scene {

namespace {
namespace fs = std::filesystem;

std::string at_index(const std::string& array, size_t i) {
    return array + "[" + std::to_string(i) + "]";
}

/// tinygltf's messages come as lines; an Error is one line.
std::string one_line(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    for (char& c : text)
        if (c == '\n') c = ';';
    return text;
}

/// Images decoded by stb_image, refused before decoding when their header claims more than
/// kMaxImagePixels (a small file could otherwise take gigabytes).
bool load_image(tinygltf::Image* image, const int index, std::string* err, std::string*, int,
                int, const unsigned char* bytes, int size, void*) {
    int width = 0, height = 0, channels = 0;
    const std::string where = "images[" + std::to_string(index) + "]";
    if (!stbi_info_from_memory(bytes, size, &width, &height, &channels)) {
        const char* reason = stbi_failure_reason();
        *err += where + ": not an image stb_image reads (" + (reason ? reason : "unknown") + ")";
        return false;
    }
    if (uint64_t(width) * uint64_t(height) > kMaxImagePixels) {
        *err += where + ": " + std::to_string(width) + "x" + std::to_string(height) +
                " pixels, more than the " + std::to_string(kMaxImagePixels) + " Lucent reads";
        return false;
    }
    unsigned char* pixels = stbi_load_from_memory(bytes, size, &width, &height, &channels, 4);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        *err += where + ": cannot decode (" + std::string(reason ? reason : "unknown") + ")";
        return false;
    }
    image->width = width;
    image->height = height;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(pixels, pixels + size_t(width) * size_t(height) * 4);
    stbi_image_free(pixels);
    return true;
}

/// The files a .gltf names (buffers, images) are found and read by tinygltf, which opens
/// them to see whether they exist (waiting for ever on a FIFO) and would read a device on
/// and on: existence is asked of the file system, and each must be a regular file.
bool named_file_exists(const std::string& path, void*) {
    std::error_code ec;
    return fs::exists(path, ec);
}

/// `gltf_path` is the .gltf's path (the callbacks' user data), named first in the error.
bool read_named_file(std::vector<unsigned char>* out, std::string* err,
                     const std::string& path, void* gltf_path) {
    try {
        require_regular_file(path, "file named by the glTF");
    } catch (const Error& e) {
        throw Error(*static_cast<const std::string*>(gltf_path) + ": " + e.what());
    }
    return tinygltf::ReadWholeFile(out, err, path, nullptr);
}

class GltfReader {
  public:
    GltfReader(std::string path, const tinygltf::Model& model)
        : m_path(std::move(path)), m_model(model) {}

    Scene read();

  private:
    [[noreturn]] void fail(const std::string& where, const std::string& message) const {
        throw Error(m_path + ": " + where + ": " + message);
    }
    void warn(const std::string& where, const std::string& message) const {
        std::fprintf(stderr, "%s: %s: %s\n", m_path.c_str(), where.c_str(), message.c_str());
    }

    /// `index` into an array of `count` entries, named `array` in the message.
    void check_index(int index, size_t count, const char* array, const std::string& where) const {
        if (index < 0 || size_t(index) >= count)
            fail(where, std::string(array) + " " + std::to_string(index) +
                            " is out of range (the file has " + std::to_string(count) + ")");
    }

    /// An accessor's elements as `width` floats each (normalised integers scaled to [0, 1]
    /// or [-1, 1], as the specification defines them), or as unsigned integers for indices.
    std::vector<float> floats(int index, int width, const std::string& where) const;
    std::vector<uint32_t> indices(int index, const std::string& where) const;
    /// The bytes of an accessor's elements: a pointer to each one's first byte.
    struct Elements {
        const unsigned char* base;
        size_t stride, count;
        int component_type, components;
        bool normalized;
    };
    Elements elements(int index, const std::string& where) const;

    unsigned material(int index, const std::string& where);
    std::string texture(int index, const std::string& where);
    int mesh(int index, const std::string& where);
    Matrix4x3 local_matrix(const tinygltf::Node& node, const std::string& where) const;

    std::string m_path;
    const tinygltf::Model& m_model;
    Scene m_scene;
    std::map<int, unsigned> m_materials;  // glTF material (-1: the default) -> Scene's
    std::map<int, int> m_meshes;          // glTF mesh -> Scene mesh, -1 when it has no triangles
    std::map<int, std::string> m_textures;  // glTF image -> Scene::textures key
};

GltfReader::Elements GltfReader::elements(int index, const std::string& where) const {
    check_index(index, m_model.accessors.size(), "accessor", where);
    const tinygltf::Accessor& a = m_model.accessors[size_t(index)];
    const std::string at = at_index("accessors", size_t(index));
    if (a.sparse.isSparse) fail(at + ".sparse", "sparse accessors are not supported");
    if (a.bufferView < 0)
        fail(at, "has no bufferView (only sparse accessors may leave it out)");
    check_index(a.bufferView, m_model.bufferViews.size(), "bufferView", at + ".bufferView");
    const tinygltf::BufferView& view = m_model.bufferViews[size_t(a.bufferView)];
    const std::string view_at = at_index("bufferViews", size_t(a.bufferView));
    check_index(view.buffer, m_model.buffers.size(), "buffer", view_at + ".buffer");
    const tinygltf::Buffer& buffer = m_model.buffers[size_t(view.buffer)];
    const int component_size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (component_size <= 0) fail(at + ".componentType", "unknown component type");
    if (components <= 0) fail(at + ".type", "unknown element type");
    const uint64_t element = uint64_t(component_size) * uint64_t(components);
    // glTF 2.0 §3.6.2.4: a stride is at most 252 bytes (so stride x count cannot overflow).
    if (view.byteStride > 252)
        fail(view_at + ".byteStride", std::to_string(view.byteStride) + " bytes; at most 252");
    const uint64_t stride = view.byteStride ? uint64_t(view.byteStride) : element;
    if (stride < element)
        fail(view_at + ".byteStride", "a stride of " + std::to_string(stride) +
                                          " bytes is less than the element's " +
                                          std::to_string(element));
    if (uint64_t(view.byteOffset) > buffer.data.size() ||
        uint64_t(view.byteLength) > buffer.data.size() - uint64_t(view.byteOffset))
        fail(view_at, "bytes " + std::to_string(view.byteOffset) + " to " +
                          std::to_string(uint64_t(view.byteOffset) + view.byteLength) +
                          " lie outside buffer " + std::to_string(view.buffer) + " of " +
                          std::to_string(buffer.data.size()) + " bytes");
    // Elements 0 .. count-1 within the view; offsets and counts are bounded by the buffer
    // first, so the sums below cannot overflow.
    if (a.count == 0) return {buffer.data.data(), size_t(stride), 0, a.componentType, components, a.normalized};
    if (uint64_t(a.byteOffset) > uint64_t(view.byteLength))
        fail(at + ".byteOffset", std::to_string(a.byteOffset) + " lies beyond bufferView " +
                                     std::to_string(a.bufferView) + " of " +
                                     std::to_string(view.byteLength) + " bytes");
    {
        const uint64_t end = uint64_t(a.byteOffset) + stride * (uint64_t(a.count) - 1) + element;
        if (uint64_t(a.count) > buffer.data.size() || end > uint64_t(view.byteLength))
            fail(at, std::to_string(a.count) + " elements from byte " +
                         std::to_string(a.byteOffset) + " overrun bufferView " +
                         std::to_string(a.bufferView) + " of " +
                         std::to_string(view.byteLength) + " bytes");
    }
    return {buffer.data.data() + view.byteOffset + a.byteOffset, size_t(stride), size_t(a.count),
            a.componentType, components, a.normalized};
}

std::vector<float> GltfReader::floats(int index, int width, const std::string& where) const {
    const Elements e = elements(index, where);
    if (e.components != width)
        fail(where, "accessor " + std::to_string(index) + " has " + std::to_string(e.components) +
                        " components per element, expected " + std::to_string(width));
    std::vector<float> out(e.count * size_t(width));
    for (size_t i = 0; i < e.count; ++i) {
        const unsigned char* p = e.base + i * e.stride;
        for (int c = 0; c < width; ++c) {
            float v = 0;
            switch (e.component_type) {
                case TINYGLTF_COMPONENT_TYPE_FLOAT: std::memcpy(&v, p + 4 * c, 4); break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                    v = float(p[c]) / (e.normalized ? 255.0f : 1.0f);
                    break;
                case TINYGLTF_COMPONENT_TYPE_BYTE:
                    v = float(int8_t(p[c]));
                    if (e.normalized) v = std::max(v / 127.0f, -1.0f);
                    break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                    uint16_t u;
                    std::memcpy(&u, p + 2 * c, 2);
                    v = float(u) / (e.normalized ? 65535.0f : 1.0f);
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_SHORT: {
                    int16_t s;
                    std::memcpy(&s, p + 2 * c, 2);
                    v = float(s);
                    if (e.normalized) v = std::max(v / 32767.0f, -1.0f);
                    break;
                }
                default:
                    fail(where, "accessor " + std::to_string(index) +
                                    ": component type " + std::to_string(e.component_type) +
                                    " is not one glTF allows for this attribute");
            }
            if (!std::isfinite(v))
                fail(where, "accessor " + std::to_string(index) + " element " +
                                std::to_string(i) + " is not finite");
            out[i * size_t(width) + size_t(c)] = v;
        }
    }
    return out;
}

std::vector<uint32_t> GltfReader::indices(int index, const std::string& where) const {
    const Elements e = elements(index, where);
    if (e.components != 1)
        fail(where, "accessor " + std::to_string(index) + " is not SCALAR, as indices are");
    std::vector<uint32_t> out(e.count);
    for (size_t i = 0; i < e.count; ++i) {
        const unsigned char* p = e.base + i * e.stride;
        switch (e.component_type) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = p[0]; break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t u;
                std::memcpy(&u, p, 2);
                out[i] = u;
                break;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&out[i], p, 4); break;
            default:
                fail(where, "accessor " + std::to_string(index) +
                                ": indices are unsigned bytes, shorts or ints");
        }
    }
    return out;
}

std::string GltfReader::texture(int index, const std::string& where) {
    check_index(index, m_model.textures.size(), "texture", where);
    const tinygltf::Texture& t = m_model.textures[size_t(index)];
    const std::string at = at_index("textures", size_t(index));
    if (t.source < 0) fail(at, "has no source image (extensions' image formats are not read)");
    check_index(t.source, m_model.images.size(), "image", at + ".source");
    auto known = m_textures.find(t.source);
    if (known != m_textures.end()) return known->second;
    const tinygltf::Image& image = m_model.images[size_t(t.source)];
    const std::string image_at = at_index("images", size_t(t.source));
    if (image.image.empty() || image.width <= 0 || image.height <= 0 || image.component != 4 ||
        image.bits != 8 ||
        image.image.size() != size_t(image.width) * size_t(image.height) * 4)
        fail(image_at, (image.uri.empty() || image.uri.rfind("data:", 0) == 0
                            ? std::string("its image")
                            : "'" + image.uri + "'") +
                           " was not loaded (a missing or unreadable file: tinygltf only "
                           "warns, so the texture would be lost)");
    TextureImage texels{unsigned(image.width), unsigned(image.height), {}};
    float to_linear[256];  // base colour textures are sRGB-encoded, alpha linear (glTF 2.0 §3.9)
    for (int i = 0; i < 256; ++i) to_linear[i] = srgb_to_linear(float(i) / 255.0f);
    texels.texels.resize(size_t(image.width) * size_t(image.height));
    for (size_t i = 0; i < texels.texels.size(); ++i) {
        const unsigned char* p = &image.image[4 * i];
        texels.texels[i] = make_float4(to_linear[p[0]], to_linear[p[1]], to_linear[p[2]],
                                       float(p[3]) / 255.0f);
    }
    const std::string key = m_path + "#" + image_at;
    m_scene.textures[key] = std::move(texels);
    return m_textures[t.source] = key;
}

unsigned GltfReader::material(int index, const std::string& where) {
    auto known = m_materials.find(index);
    if (known != m_materials.end()) return known->second;
    Material m;
    if (index < 0) {
        // The specification's default material: white, fully metallic, fully rough.
        m.name = "glTF default";
        m.diffuse = make_float3(1.0f);
        m.kind = MaterialKind::kMetal;
        m.roughness = 1.0f;
    } else {
        check_index(index, m_model.materials.size(), "material", where);
        const tinygltf::Material& g = m_model.materials[size_t(index)];
        const std::string at = at_index("materials", size_t(index));
        const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
        m.name = g.name.empty() ? at : g.name;
        if (pbr.baseColorFactor.size() != 4)
            fail(at + ".pbrMetallicRoughness.baseColorFactor", "expected 4 numbers");
        m.diffuse = make_float3(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                                float(pbr.baseColorFactor[2]));
        if (!(min_component(m.diffuse) >= 0 && max_component(m.diffuse) <= 1))
            fail(at + ".pbrMetallicRoughness.baseColorFactor", "expected values in [0, 1]");
        const float metallic = float(pbr.metallicFactor), roughness = float(pbr.roughnessFactor);
        if (!(metallic >= 0 && metallic <= 1))
            fail(at + ".pbrMetallicRoughness.metallicFactor", "expected a value in [0, 1]");
        if (!(roughness >= 0 && roughness <= 1))
            fail(at + ".pbrMetallicRoughness.roughnessFactor", "expected a value in [0, 1]");
        // The path tracer has a conductor and a coated diffuse, not a blend of the two: a
        // material at least half metallic is the conductor, the rest glTF's dielectric base
        // (a GGX specular layer of F0 0.04, ior 1.5, over the diffuse base colour).
        m.kind = metallic >= 0.5f ? MaterialKind::kMetal : MaterialKind::kCoated;
        m.roughness = roughness;
        m.ior = 1.5f;
        if (pbr.baseColorTexture.index >= 0) {
            if (pbr.baseColorTexture.texCoord != 0)
                warn(at + ".pbrMetallicRoughness.baseColorTexture.texCoord",
                     "only TEXCOORD_0 is read; the texture is applied with it");
            m.diffuse_texture =
                texture(pbr.baseColorTexture.index, at + ".pbrMetallicRoughness.baseColorTexture.index");
        }
        if (g.emissiveFactor.size() != 3) fail(at + ".emissiveFactor", "expected 3 numbers");
        float strength = 1.0f;
        auto ext = g.extensions.find("KHR_materials_emissive_strength");
        if (ext != g.extensions.end() && ext->second.Has("emissiveStrength")) {
            const tinygltf::Value& s = ext->second.Get("emissiveStrength");
            if (!s.IsNumber() || !(s.GetNumberAsDouble() >= 0))
                fail(at + ".extensions.KHR_materials_emissive_strength.emissiveStrength",
                     "expected a number >= 0");
            strength = float(s.GetNumberAsDouble());
        }
        m.emission = strength * make_float3(float(g.emissiveFactor[0]), float(g.emissiveFactor[1]),
                                            float(g.emissiveFactor[2]));
        if (!(min_component(m.emission) >= 0) || !std::isfinite(max_component(m.emission)))
            fail(at + ".emissiveFactor", "expected finite values >= 0");
        if (g.emissiveTexture.index >= 0 && max_component(m.emission) > 0)
            warn(at + ".emissiveTexture", "emissive textures are not read; the material emits "
                                          "its emissiveFactor uniformly");
    }
    const unsigned id = unsigned(m_scene.materials.size());
    m_scene.materials.push_back(m);
    return m_materials[index] = id;
}

int GltfReader::mesh(int index, const std::string& where) {
    auto known = m_meshes.find(index);
    if (known != m_meshes.end()) return known->second;
    check_index(index, m_model.meshes.size(), "mesh", where);
    const tinygltf::Mesh& g = m_model.meshes[size_t(index)];
    const std::string at = at_index("meshes", size_t(index));
    Mesh mesh;
    mesh.name = g.name.empty() ? at : g.name;
    bool all_normals = true, any_uvs = false;
    std::vector<std::vector<float3>> normals_of;  // per primitive, to join when all have them
    for (size_t p = 0; p < g.primitives.size(); ++p) {
        const tinygltf::Primitive& prim = g.primitives[p];
        const std::string pat = at + ".primitives[" + std::to_string(p) + "]";
        static const char* const kModes[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
        if (prim.mode >= 0 && prim.mode <= 3) {
            warn(pat + ".mode", std::string("mode ") + std::to_string(prim.mode) + " (" +
                                    kModes[prim.mode] +
                                    ") draws no triangles; Lucent renders triangles, skipped");
            continue;
        }
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(pat + ".mode", "unknown primitive mode " + std::to_string(prim.mode));
        auto position = prim.attributes.find("POSITION");
        if (position == prim.attributes.end())
            fail(pat + ".attributes", "no POSITION attribute");
        const std::vector<float> pos = floats(position->second, 3, pat + ".attributes.POSITION");
        const size_t vertices = pos.size() / 3;
        const uint32_t base = uint32_t(mesh.positions.size());
        if (uint64_t(base) + vertices > 0xffffffffu) fail(pat, "more than 2^32 vertices in a mesh");
        for (size_t v = 0; v < vertices; ++v)
            mesh.positions.push_back(make_float3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
        auto normal = prim.attributes.find("NORMAL");
        std::vector<float3> prim_normals;
        if (normal != prim.attributes.end()) {
            const std::vector<float> n = floats(normal->second, 3, pat + ".attributes.NORMAL");
            if (n.size() / 3 != vertices)
                fail(pat + ".attributes.NORMAL", "has " + std::to_string(n.size() / 3) +
                                                     " elements, POSITION " +
                                                     std::to_string(vertices));
            for (size_t v = 0; v < vertices; ++v)
                prim_normals.push_back(make_float3(n[3 * v], n[3 * v + 1], n[3 * v + 2]));
        } else {
            all_normals = false;
        }
        normals_of.push_back(std::move(prim_normals));
        auto uv = prim.attributes.find("TEXCOORD_0");
        if (uv != prim.attributes.end()) {
            const std::vector<float> t = floats(uv->second, 2, pat + ".attributes.TEXCOORD_0");
            if (t.size() / 2 != vertices)
                fail(pat + ".attributes.TEXCOORD_0", "has " + std::to_string(t.size() / 2) +
                                                         " elements, POSITION " +
                                                         std::to_string(vertices));
            if (!any_uvs) mesh.uvs.assign(base, make_float2(0.0f, 0.0f));
            any_uvs = true;
            // glTF's v runs down the image, OBJ's (which the samples' programs read) up.
            for (size_t v = 0; v < vertices; ++v)
                mesh.uvs.push_back(make_float2(t[2 * v], 1.0f - t[2 * v + 1]));
        } else if (any_uvs) {
            mesh.uvs.resize(mesh.positions.size(), make_float2(0.0f, 0.0f));
        }
        std::vector<uint32_t> order;
        if (prim.indices >= 0) {
            order = indices(prim.indices, pat + ".indices");
            for (size_t i = 0; i < order.size(); ++i)
                if (order[i] >= vertices)
                    fail(pat + ".indices", "index " + std::to_string(order[i]) + " (element " +
                                               std::to_string(i) + ") is out of range (POSITION has " +
                                               std::to_string(vertices) + " vertices)");
        } else {
            order.resize(vertices);
            for (size_t v = 0; v < vertices; ++v) order[v] = uint32_t(v);
        }
        std::vector<uint3> triangles;
        if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
            if (order.size() % 3 != 0)
                fail(pat, std::to_string(order.size()) +
                              " vertices or indices for TRIANGLES, not a multiple of 3");
            for (size_t i = 0; i + 2 < order.size(); i += 3)
                triangles.push_back(make_uint3(order[i], order[i + 1], order[i + 2]));
        } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t i = 0; i + 2 < order.size(); ++i)  // every other one flipped: one winding
                triangles.push_back(i % 2 ? make_uint3(order[i + 1], order[i], order[i + 2])
                                          : make_uint3(order[i], order[i + 1], order[i + 2]));
        } else {
            for (size_t i = 1; i + 1 < order.size(); ++i)
                triangles.push_back(make_uint3(order[0], order[i], order[i + 1]));
        }
        const unsigned mat = material(prim.material, pat + ".material");
        for (const uint3& t : triangles) {
            mesh.indices.push_back(make_uint3(t.x + base, t.y + base, t.z + base));
            mesh.materials.push_back(mat);
        }
    }
    if (all_normals)
        for (auto& n : normals_of) mesh.normals.insert(mesh.normals.end(), n.begin(), n.end());
    if (mesh.indices.empty()) {
        warn(at, "has no triangles; the nodes that use it draw nothing");
        return m_meshes[index] = -1;
    }
    if (any_uvs) mesh.uvs.resize(mesh.positions.size(), make_float2(0.0f, 0.0f));
    const int id = int(m_scene.meshes.size());
    m_scene.meshes.push_back(std::move(mesh));
    return m_meshes[index] = id;
}

Matrix4x3 GltfReader::local_matrix(const tinygltf::Node& node, const std::string& where) const {
    auto finite = [&](const std::vector<double>& v, const char* key) {
        for (double x : v)
            if (!std::isfinite(x)) fail(where + "." + key, "a value is not finite");
    };
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) fail(where + ".matrix", "expected 16 numbers");
        finite(node.matrix, "matrix");
        const auto& c = node.matrix;  // column-major; the last row must be 0 0 0 1 (affine)
        if (c[3] != 0 || c[7] != 0 || c[11] != 0 || c[15] != 1)
            fail(where + ".matrix", "not affine (its last row is not 0 0 0 1)");
        return Matrix4x3{{float(c[0]), float(c[4]), float(c[8]), float(c[12]), float(c[1]),
                          float(c[5]), float(c[9]), float(c[13]), float(c[2]), float(c[6]),
                          float(c[10]), float(c[14])}};
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(where + ".translation", "expected 3 numbers");
        finite(node.translation, "translation");
        std::copy(node.translation.begin(), node.translation.end(), t);
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4)
            fail(where + ".rotation", "expected a quaternion of 4 numbers (x, y, z, w)");
        finite(node.rotation, "rotation");
        std::copy(node.rotation.begin(), node.rotation.end(), q);
        const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(n > 0)) fail(where + ".rotation", "a zero quaternion is no rotation");
        for (double& x : q) x /= n;  // exporters round them; unit-length is what is meant
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(where + ".scale", "expected 3 numbers");
        finite(node.scale, "scale");
        std::copy(node.scale.begin(), node.scale.end(), s);
    }
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                         2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                         2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    Matrix4x3 m{};  // T * R * S
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m.m[i * 4 + j] = float(r[i * 3 + j] * s[j]);
        m.m[i * 4 + 3] = float(t[i]);
    }
    return m;
}

Scene GltfReader::read() {
    m_scene.name = fs::path(m_path).stem().string();
    static const char* const kSupported[] = {"KHR_lights_punctual",
                                             "KHR_materials_emissive_strength"};
    for (size_t i = 0; i < m_model.extensionsRequired.size(); ++i) {
        const std::string& e = m_model.extensionsRequired[i];
        if (std::find(std::begin(kSupported), std::end(kSupported), e) == std::end(kSupported))
            fail(at_index("extensionsRequired", i),
                 "the file requires " + e + ", which Lucent does not read");
    }

    // The scene to draw: "scene", else the first; a file without scenes draws its root nodes.
    std::vector<int> roots;
    std::string roots_at;
    if (!m_model.scenes.empty()) {
        int chosen = m_model.defaultScene >= 0 ? m_model.defaultScene : 0;
        check_index(chosen, m_model.scenes.size(), "scene", "scene");
        roots = m_model.scenes[size_t(chosen)].nodes;
        roots_at = at_index("scenes", size_t(chosen)) + ".nodes";
    } else {
        std::vector<bool> child(m_model.nodes.size(), false);
        for (const tinygltf::Node& n : m_model.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
        for (size_t i = 0; i < child.size(); ++i)
            if (!child[i]) roots.push_back(int(i));
        roots_at = "nodes";
    }

    // Depth first with an explicit stack (a deep hierarchy must not overflow the C++ one);
    // `on_path` catches a node that is its own ancestor, which would never end.
    struct Visit {
        int node;
        Matrix4x3 parent;
        std::string where;
        bool leave;
    };
    std::vector<Visit> stack;
    for (size_t i = roots.size(); i-- > 0;)
        stack.push_back({roots[i], identity_matrix(), roots_at + "[" + std::to_string(i) + "]", false});
    std::vector<bool> on_path(m_model.nodes.size(), false), seen(m_model.nodes.size(), false);
    std::vector<int> camera_node(m_model.cameras.size(), -1);
    std::vector<Matrix4x3> camera_world(m_model.cameras.size());
    while (!stack.empty()) {
        Visit v = std::move(stack.back());
        stack.pop_back();
        if (v.leave) {
            on_path[size_t(v.node)] = false;
            continue;
        }
        check_index(v.node, m_model.nodes.size(), "node", v.where);
        if (on_path[size_t(v.node)])
            fail(v.where, "node " + std::to_string(v.node) + " is its own ancestor (a cycle)");
        // glTF's nodes form disjoint trees (§3.5.1): a node reached twice has two parents,
        // and a file of such nodes could ask for exponentially many visits.
        if (seen[size_t(v.node)])
            fail(v.where, "node " + std::to_string(v.node) +
                              " is reached a second time (a node has one parent at most)");
        seen[size_t(v.node)] = true;
        const tinygltf::Node& node = m_model.nodes[size_t(v.node)];
        const std::string at = at_index("nodes", size_t(v.node));
        const Matrix4x3 world = multiply(v.parent, local_matrix(node, at));
        if (node.mesh != -1) {
            const int id = mesh(node.mesh, at + ".mesh");
            Matrix4x3 inverse;
            if (id >= 0 && !invert(world, inverse))
                warn(at, "its world transform is singular (a zero scale); its mesh is not drawn");
            else if (id >= 0)
                m_scene.instances.push_back({unsigned(id), world});
        }
        if (node.camera != -1) {
            check_index(node.camera, m_model.cameras.size(), "camera", at + ".camera");
            if (camera_node[size_t(node.camera)] < 0) {
                camera_node[size_t(node.camera)] = v.node;
                camera_world[size_t(node.camera)] = world;
            }
        }
        auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end()) {
            const std::string lat = at + ".extensions.KHR_lights_punctual.light";
            if (!light->second.Has("light") || !light->second.Get("light").IsInt())
                fail(lat, "expected the index of a light");
            const int index = light->second.Get("light").GetNumberAsInt();
            check_index(index, m_model.lights.size(), "light", lat);
            const tinygltf::Light& l = m_model.lights[size_t(index)];
            const std::string light_at = "extensions.KHR_lights_punctual.lights[" +
                                         std::to_string(index) + "]";
            float3 colour = make_float3(1.0f);
            if (!l.color.empty()) {
                if (l.color.size() != 3) fail(light_at + ".color", "expected 3 numbers");
                colour = make_float3(float(l.color[0]), float(l.color[1]), float(l.color[2]));
            }
            const float3 intensity = colour * float(l.intensity);
            if (!(min_component(intensity) >= 0) || !std::isfinite(max_component(intensity)))
                fail(light_at, "color and intensity must be finite and >= 0");
            if (l.type == "point")
                m_scene.point_lights.push_back(
                    {transform_point(world, make_float3(0.0f)), intensity});
            else if (l.type == "spot" || l.type == "directional")
                warn(lat, "a " + l.type + " light; the samples have point and area lights only, "
                          "skipped");
            else
                fail(light_at + ".type", "expected \"point\", \"spot\" or \"directional\"");
        }
        stack.push_back({v.node, {}, {}, true});
        on_path[size_t(v.node)] = true;
        for (size_t c = node.children.size(); c-- > 0;)
            stack.push_back({node.children[c], world, at + ".children[" + std::to_string(c) + "]",
                             false});
    }
    if (m_scene.instances.empty()) fail("scenes", "the scene draws no triangles");

    for (size_t i = 0; i < m_model.cameras.size(); ++i) {
        const tinygltf::Camera& c = m_model.cameras[i];
        const std::string at = at_index("cameras", i);
        Camera camera;
        if (c.type != "perspective") {
            camera.unusable = m_path + ": " + at + ": an " + c.type +
                              " camera; Lucent's cameras are pinholes (perspective)";
        } else if (camera_node[i] < 0) {
            camera.unusable = m_path + ": " + at + ": no node of the scene places it";
        } else {
            const float yfov = float(c.perspective.yfov) * 180.0f / 3.14159265f;
            if (!(yfov > 0 && yfov < 180))
                fail(at + ".perspective.yfov", "expected a vertical field of view in (0, pi)");
            // glTF cameras look down their -z with +y up, in their node's frame.
            const Matrix4x3& w = camera_world[i];
            camera.eye = transform_point(w, make_float3(0.0f));
            const float3 forward = transform_vector(w, make_float3(0, 0, -1));
            const float3 up = transform_vector(w, make_float3(0, 1, 0));
            if (!(length(forward) > 0) || !(length(cross(forward, up)) > 0))
                fail(at_index("nodes", size_t(camera_node[i])),
                     "the camera's node transform is singular");
            camera.look = camera.eye + normalize(forward);
            camera.up = normalize(up);
            camera.fov_degrees = yfov;
        }
        m_scene.cameras.push_back(camera);
    }
    auto first = std::find_if(m_scene.cameras.begin(), m_scene.cameras.end(),
                              [](const Camera& c) { return c.unusable.empty(); });
    m_scene.camera = first != m_scene.cameras.end() ? *first : framing_camera(m_scene);
    return std::move(m_scene);
}

std::vector<unsigned char> read_bytes(const std::string& path) {
    require_regular_file(path, "glTF file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open the glTF file (check the path)");
    return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

Scene load_gltf_scene(const std::string& path) {
    try {
        const std::vector<unsigned char> bytes = read_bytes(path);
        if (bytes.size() > 0xffffffffu) throw Error(path + ": larger than 4 GiB, glTF's limit");
        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(load_image, nullptr);
        loader.SetFsCallbacks({&named_file_exists, &tinygltf::ExpandFilePath, &read_named_file,
                               &tinygltf::WriteWholeFile,
                               const_cast<std::string*>(&path)});
        tinygltf::Model model;
        std::string err, warn;
        const std::string base = fs::path(path).parent_path().string();
        // By content, not by extension: a .gltf that is a GLB container reads as one.
        const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
        // JSON text holds no NUL byte, and the JSON parser ends its input at one: what
        // follows it would be ignored without a word.
        if (!binary && !bytes.empty())  // an empty vector's data() may be null
            if (const void* nul = std::memchr(bytes.data(), 0, bytes.size()))
                throw Error(path + ": a NUL byte at byte " +
                            std::to_string(static_cast<const unsigned char*>(nul) - bytes.data()) +
                            ": a .gltf file is JSON text (this one is damaged, sparse or not "
                            "glTF)");
        const bool ok =
            binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                 unsigned(bytes.size()), base)
                   : loader.LoadASCIIFromString(&model, &err, &warn,
                                                reinterpret_cast<const char*>(bytes.data()),
                                                unsigned(bytes.size()), base);
        if (!ok)
            throw Error(path + ": " +
                        (err.empty() ? std::string("tinygltf could not read the file")
                                     : one_line(err)));
        if (!warn.empty()) std::fprintf(stderr, "%s: %s\n", path.c_str(), one_line(warn).c_str());
        return GltfReader(path, model).read();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw Error(path + ": out of memory reading the glTF file");
    } catch (const std::exception& e) {  // tinygltf's JSON library, on input it did not expect
        throw Error(path + ": " + e.what());
    }
}

}  // namespace lucent::scene
