// An OpenEXR header's data window against a documented bound and against what the file
// could hold, before any pixel is allocated: a 1.2 MB file declaring 100,000 x 100,000
// pixels asked for 120 GB (std::bad_alloc), one of 132 KB declaring 11,000 x 11,000 took
// 1.4 GB before OpenEXR noticed the missing lines.
#pragma once

#if LUCENT_HAVE_OPENEXR
#include <ImfHeader.h>

#include <cstdint>
#include <string>

namespace lucent::scene {

/// Throws lucent::Error naming `path` when the header's data window is empty, holds more
/// than kMaxImagePixels, or needs more bytes than the file's `file_bytes`: every chunk (a
/// block of scanlines, or a tile) takes 8 bytes in the offset table and at least 8 of its
/// own (OpenEXR file layout: y or tile coordinates, and the data size), and an
/// uncompressed scanline all its pixels' bytes.
void check_exr_header(const std::string& path, const Imf::Header& header, uint64_t file_bytes);

}  // namespace lucent::scene
#endif
