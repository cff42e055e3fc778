#include "scene/exr_encoder.h"

#include "lucent/error.h"

#if LUCENT_HAVE_OPENEXR
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cstring>
#include <set>

#include "scene/exr_header_check.h"
#include "scene/input_file.h"
#endif

namespace lucent::scene {

#if LUCENT_HAVE_OPENEXR
namespace {
/// An Imf::OStream into a byte vector, so the file is written whole (and atomically) by
/// write_image like every other format.
class MemoryStream : public Imf::OStream {
  public:
    explicit MemoryStream(std::vector<unsigned char>& bytes)
        : Imf::OStream("memory"), m_bytes(bytes) {}
    void write(const char c[], int n) override {
        if (m_position + size_t(n) > m_bytes.size()) m_bytes.resize(m_position + size_t(n));
        std::memcpy(m_bytes.data() + m_position, c, size_t(n));
        m_position += size_t(n);
    }
    uint64_t tellp() override { return m_position; }
    void seekp(uint64_t position) override { m_position = size_t(position); }

  private:
    std::vector<unsigned char>& m_bytes;
    size_t m_position = 0;
};
}  // namespace

bool exr_supported() {
    return true;
}

std::vector<unsigned char> encode_exr(const std::string& path, const Image& image,
                                      const ExrExtras& extras) {
    const size_t pixels = size_t(image.width) * image.height;
    std::set<std::string> names = {"R", "G", "B"};
    for (const ExrChannel& c : extras.channels) {
        if (c.name.empty() || !names.insert(c.name).second)
            throw Error("cannot write '" + path + "': EXR channel name '" + c.name +
                        "' is empty or given twice");
        if (c.values.size() != pixels)
            throw Error("cannot write '" + path + "': EXR channel '" + c.name + "' has " +
                        std::to_string(c.values.size()) + " values for " +
                        std::to_string(pixels) + " pixels");
    }
    std::vector<unsigned char> bytes;
    try {
        Imf::Header header(int(image.width), int(image.height));
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
        for (const ExrChannel& c : extras.channels)
            header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
        for (const auto& [name, value] : extras.attributes)
            header.insert(name, Imf::StringAttribute(value));
        // float3 pixels, row-major from the top: each channel is a strided view of them.
        char* base = const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data()));
        const size_t xs = sizeof(float3), ys = sizeof(float3) * image.width;
        Imf::FrameBuffer frame;
        frame.insert("R", Imf::Slice(Imf::FLOAT, base + offsetof(float3, x), xs, ys));
        frame.insert("G", Imf::Slice(Imf::FLOAT, base + offsetof(float3, y), xs, ys));
        frame.insert("B", Imf::Slice(Imf::FLOAT, base + offsetof(float3, z), xs, ys));
        for (const ExrChannel& c : extras.channels) {
            char* values = const_cast<char*>(reinterpret_cast<const char*>(c.values.data()));
            frame.insert(c.name, Imf::Slice(Imf::FLOAT, values, sizeof(float),
                                            sizeof(float) * image.width));
        }
        MemoryStream stream(bytes);
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(int(image.height));
    } catch (const std::exception& e) {
        throw Error("cannot write '" + path + "': OpenEXR encoding failed: " + e.what());
    }
    return bytes;
}

ExrFile read_exr_file(const std::string& path) {
    require_regular_file(path, "OpenEXR image");  // a FIFO would block OpenEXR's open
    try {
        Imf::InputFile file(path.c_str());
        check_exr_header(path, file.header(), file_size(path));
        const Imath::Box2i window = file.header().dataWindow();
        ExrFile out;
        Image& image = out.image;
        image.width = unsigned(window.max.x - window.min.x + 1);
        image.height = unsigned(window.max.y - window.min.y + 1);
        const size_t pixels = size_t(image.width) * image.height;
        const size_t origin = size_t(window.min.y) * image.width + size_t(window.min.x);
        image.pixels.resize(pixels);
        char* base = reinterpret_cast<char*>(image.pixels.data()) - origin * sizeof(float3);
        const size_t xs = sizeof(float3), ys = sizeof(float3) * image.width;
        Imf::FrameBuffer frame;
        frame.insert("R", Imf::Slice(Imf::FLOAT, base + offsetof(float3, x), xs, ys));
        frame.insert("G", Imf::Slice(Imf::FLOAT, base + offsetof(float3, y), xs, ys));
        frame.insert("B", Imf::Slice(Imf::FLOAT, base + offsetof(float3, z), xs, ys));
        const Imf::ChannelList& list = file.header().channels();
        for (auto c = list.begin(); c != list.end(); ++c) {
            const std::string name = c.name();
            if (name == "R" || name == "G" || name == "B") continue;
            std::vector<float>& values = out.channels[name];
            values.resize(pixels);
            char* at = reinterpret_cast<char*>(values.data()) - origin * sizeof(float);
            frame.insert(name, Imf::Slice(Imf::FLOAT, at, sizeof(float),
                                          sizeof(float) * image.width));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        for (auto a = file.header().begin(); a != file.header().end(); ++a)
            if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&a.attribute()))
                out.attributes[a.name()] = text->value();
        return out;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error("cannot read '" + path + "': " + e.what());
    }
}

Image read_exr(const std::string& path) {
    return read_exr_file(path).image;
}
#else
bool exr_supported() {
    return false;
}

Image read_exr(const std::string& path) {
    throw Error("cannot read '" + path + "': this build has no OpenEXR");
}

ExrFile read_exr_file(const std::string& path) {
    throw Error("cannot read '" + path + "': this build has no OpenEXR");
}

std::vector<unsigned char> encode_exr(const std::string& path, const Image&, const ExrExtras&) {
    throw Error("cannot write '" + path +
                "': this build has no OpenEXR (install libopenexr-dev and reconfigure); use "
                ".pfm for a float image");
}
#endif

}  // namespace lucent::scene
