// PNG and PFM files. PNG goes through Debian's libstb (stb_image_write/stb_image); PFM is
// simple enough to write by hand. Every write is atomic: encode in memory, write a temporary
// file beside the target, rename over it.
#include "scene/image_io.h"

#include "scene/temp_file_cleanup.h"

#include "scene/exr_encoder.h"

#include <fcntl.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

#include "lucent/display.h"
#include "lucent/error.h"

namespace lucent::scene {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void check_image(const std::string& path, const Image& image) {
    if (image.width == 0 || image.height == 0)
        throw Error("cannot write '" + path + "': the image is empty (" +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + ")");
    if (image.pixels.size() != size_t(image.width) * image.height)
        throw Error("cannot write '" + path + "': the image is " + std::to_string(image.width) +
                    "x" + std::to_string(image.height) + " but holds " +
                    std::to_string(image.pixels.size()) + " pixels");
}

std::vector<unsigned char> encode_png_rgb(const std::string& path, unsigned width,
                                          unsigned height, const unsigned char* rgb) {
    std::vector<unsigned char> bytes;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        auto* begin = static_cast<unsigned char*>(data);
        out->insert(out->end(), begin, begin + size);
    };
    if (!stbi_write_png_to_func(append, &bytes, int(width), int(height), 3, rgb, int(width) * 3))
        throw Error("cannot write '" + path + "': PNG encoding failed");
    return bytes;
}

std::vector<unsigned char> encode_png(const std::string& path, const Image& image) {
    return encode_png_rgb(path, image.width, image.height, to_srgb8(image).data());
}

// Portable float map: header "PF", size, scale (negative = little-endian), then rows from
// the bottom of the image up.
std::vector<unsigned char> encode_pfm(const Image& image) {
    const std::string header =
        "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
    const size_t row_bytes = size_t(image.width) * 3 * sizeof(float);
    std::vector<unsigned char> bytes(header.begin(), header.end());
    bytes.reserve(header.size() + row_bytes * image.height);
    static_assert(std::endian::native == std::endian::little, "PFM writer assumes little-endian");
    for (unsigned y = image.height; y-- > 0;) {
        const float3* row = image.pixels.data() + size_t(y) * image.width;
        for (unsigned x = 0; x < image.width; ++x) {
            const float rgb[3] = {row[x].x, row[x].y, row[x].z};
            const auto* p = reinterpret_cast<const unsigned char*>(rgb);
            bytes.insert(bytes.end(), p, p + sizeof(rgb));
        }
    }
    return bytes;
}

// A temporary file in the target's directory, so the final rename stays on one file system
// and is atomic; removed unless commit() succeeds.
class TempFile {
  public:
    explicit TempFile(const std::string& target) : m_target(target) {
        fs::path dir = fs::path(target).parent_path();
        if (dir.empty()) dir = ".";
        std::string name = ".";  // hidden, so a crash mid-write leaves no visible debris
        name += fs::path(target).filename().string();
        name += ".XXXXXX";
        m_path = (dir / name).string();
        m_fd = ::mkstemp(m_path.data());
        if (m_fd < 0) fail("cannot create a file in '" + dir.string() + "'");
        m_guard = std::make_unique<TempFileGuard>(m_path);  // removed if a signal ends us
    }
    ~TempFile() {
        if (m_fd >= 0) ::close(m_fd);
        if (!m_committed) ::unlink(m_path.c_str());
        m_guard.reset();
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    void write(const std::vector<unsigned char>& bytes) {
        size_t done = 0;
        while (done < bytes.size()) {
            ssize_t n = ::write(m_fd, bytes.data() + done, bytes.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) fail("write failed");
            done += size_t(n);
        }
    }

    void commit() {
        // mkstemp makes the file 0600; give it the mode a plain fopen would (0666 & ~umask).
        mode_t mask = ::umask(0);
        ::umask(mask);
        ::fchmod(m_fd, 0666 & ~mask);
        int fd = m_fd;
        m_fd = -1;
        if (::close(fd) != 0) fail("write failed");
        if (::rename(m_path.c_str(), m_target.c_str()) != 0) fail("cannot replace the file");
        m_committed = true;
        m_guard.reset();  // the path is the target's now: a signal must not remove it
    }

  private:
    [[noreturn]] void fail(const std::string& what) const {
        throw Error("cannot write '" + m_target + "': " + what + ": " + std::strerror(errno));
    }
    std::string m_target, m_path;
    int m_fd = -1;
    bool m_committed = false;
    std::unique_ptr<TempFileGuard> m_guard;
};

}  // namespace

std::vector<unsigned char> to_srgb8(const Image& image) {
    std::vector<unsigned char> rgb(image.pixels.size() * 3);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const float3& p = image.pixels[i];
        rgb[3 * i + 0] = srgb8_from_linear(p.x);
        rgb[3 * i + 1] = srgb8_from_linear(p.y);
        rgb[3 * i + 2] = srgb8_from_linear(p.z);
    }
    return rgb;
}

std::span<const ImageFormat> image_formats() {
    static constexpr ImageFormat kFormats[] = {
        {".png", "8-bit sRGB"}, {".exr", "OpenEXR, float"}, {".pfm", "32-bit float, linear"}};
    return kFormats;
}

std::string image_formats_text() {
    const auto formats = image_formats();
    std::string text = "must end in ";
    for (size_t i = 0; i < formats.size(); ++i) {
        if (i > 0) text += i + 1 == formats.size() ? " or " : ", ";
        text += std::string(formats[i].extension) + " (" + formats[i].what + ")";
    }
    return text;
}

bool has_image_extension(const std::string& path) {
    const std::string ext = lower_extension(path);
    for (const ImageFormat& f : image_formats())
        if (ext == f.extension) return true;
    return false;
}

void write_image(const std::string& path, const Image& image) {
    write_image(path, image, ExrExtras{});
}

void write_image(const std::string& path, const Image& image, const ExrExtras& extras) {
    const std::string ext = lower_extension(path);
    if (!has_image_extension(path))
        throw Error("cannot write '" + path + "': " +
                    (ext.empty() ? std::string("no file extension")
                                 : "unknown image extension '" + ext + "'") +
                    "; the name " + image_formats_text());
    if (ext != ".exr" && !extras.empty())
        throw Error("cannot write '" + path + "': alpha, AOV layers and metadata need an .exr "
                    "file (OpenEXR holds extra channels; " + ext + " does not)");
    check_image(path, image);
    std::vector<unsigned char> bytes = ext == ".png"   ? encode_png(path, image)
                                       : ext == ".exr" ? encode_exr(path, image, extras)
                                                       : encode_pfm(image);
    TempFile file(path);
    file.write(bytes);
    file.commit();
}

void write_png_rgba8(const std::string& path, unsigned width, unsigned height,
                     const std::vector<unsigned char>& rgba) {
    if (width == 0 || height == 0 || rgba.size() != size_t(width) * height * 4)
        throw Error("cannot write '" + path + "': " + std::to_string(rgba.size()) +
                    " bytes are not a " + std::to_string(width) + "x" + std::to_string(height) +
                    " RGBA image");
    std::vector<unsigned char> rgb(size_t(width) * height * 3);
    for (size_t i = 0; i < size_t(width) * height; ++i)
        std::copy_n(rgba.data() + 4 * i, 3, rgb.data() + 3 * i);
    TempFile file(path);
    file.write(encode_png_rgb(path, width, height, rgb.data()));
    file.commit();
}

Image8 read_png8(const std::string& path) {
    int width = 0, height = 0, channels = 0;
    std::unique_ptr<unsigned char, void (*)(void*)> data(
        stbi_load(path.c_str(), &width, &height, &channels, 3), stbi_image_free);
    if (!data) {
        const char* reason = stbi_failure_reason();
        throw Error("cannot read '" + path + "': " +
                    (std::filesystem::exists(path) ? std::string(reason ? reason : "not a PNG")
                                                   : std::string("no such file")));
    }
    Image8 image;
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.rgb.assign(data.get(), data.get() + size_t(width) * height * 3);
    return image;
}

size_t count_differing_pixels(const Image8& a, const Image8& b, int threshold) {
    if (a.width != b.width || a.height != b.height)
        throw Error("count_differing_pixels: images differ in size (" + std::to_string(a.width) +
                    "x" + std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                    std::to_string(b.height) + ")");
    size_t differing = 0;
    for (size_t i = 0; i + 2 < a.rgb.size() && i + 2 < b.rgb.size(); i += 3) {
        for (int c = 0; c < 3; ++c) {
            if (std::abs(int(a.rgb[i + c]) - int(b.rgb[i + c])) > threshold) {
                ++differing;
                break;
            }
        }
    }
    return differing;
}

}  // namespace lucent::scene
