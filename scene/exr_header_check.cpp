#include "scene/exr_header_check.h"

#if LUCENT_HAVE_OPENEXR
#include <ImfChannelList.h>
#include <ImfTileDescription.h>

#include "lucent/error.h"
#include "scene/texture_image.h"

namespace lucent::scene {

namespace {
/// Scanlines per chunk of each compression (OpenEXR's "Technical Introduction", table of
/// compression methods).
uint64_t lines_per_chunk(Imf::Compression c) {
    switch (c) {
        case Imf::ZIP_COMPRESSION:
        case Imf::PXR24_COMPRESSION: return 16;
        case Imf::PIZ_COMPRESSION:
        case Imf::B44_COMPRESSION:
        case Imf::B44A_COMPRESSION:
        case Imf::DWAA_COMPRESSION: return 32;
        case Imf::DWAB_COMPRESSION: return 256;
        default: return 1;  // none, RLE, ZIPS
    }
}
}  // namespace

void check_exr_header(const std::string& path, const Imf::Header& header, uint64_t file_bytes) {
    const Imath::Box2i window = header.dataWindow();
    const int64_t width = int64_t(window.max.x) - window.min.x + 1;
    const int64_t height = int64_t(window.max.y) - window.min.y + 1;
    const std::string size = std::to_string(width) + " x " + std::to_string(height);
    if (width <= 0 || height <= 0)
        throw Error("cannot read '" + path + "': its data window is empty (" + size + ")");
    if (uint64_t(width) * uint64_t(height) > kMaxImagePixels)
        throw Error("cannot read '" + path + "': it declares " + size + " pixels, more than the " +
                    std::to_string(kMaxImagePixels) +
                    " an image may have; resize it (or check that the file is not damaged)");
    uint64_t chunks = 0;
    if (header.hasTileDescription()) {
        const Imf::TileDescription& tile = header.tileDescription();
        const uint64_t tx = std::max(1u, tile.xSize), ty = std::max(1u, tile.ySize);
        chunks = ((uint64_t(width) + tx - 1) / tx) * ((uint64_t(height) + ty - 1) / ty);
    } else {
        const uint64_t lines = lines_per_chunk(header.compression());
        chunks = (uint64_t(height) + lines - 1) / lines;
    }
    uint64_t needed = chunks * 16;
    if (header.compression() == Imf::NO_COMPRESSION && !header.hasTileDescription()) {
        uint64_t pixel_bytes = 0;
        for (auto c = header.channels().begin(); c != header.channels().end(); ++c)
            pixel_bytes += c.channel().type == Imf::HALF ? 2 : 4;
        needed += uint64_t(width) * uint64_t(height) * pixel_bytes;
    }
    if (needed > file_bytes)
        throw Error("cannot read '" + path + "': it declares " + size + " pixels, which need at least " +
                    std::to_string(needed) + " bytes, but the file has " +
                    std::to_string(file_bytes) + "; it is truncated or its header is wrong");
}

}  // namespace lucent::scene
#endif
