// The lines of a text file (OBJ, MTL), read in 1 MiB blocks with the progress reported, and
// refused early when the file is not text: a NUL byte (a sparse file, a copy of /dev/zero,
// a binary file given the wrong name) or a line longer than kMaxLineBytes would otherwise
// be read as one line of gigabytes.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "scene/load_progress.h"

namespace lucent::scene {

/// The longest line a text scene file may have: 1 MiB, some 40,000 vertices of one face
/// written as "v/vt/vn" triples of 7-digit indices.
inline constexpr size_t kMaxLineBytes = size_t(1) << 20;

class LineReader {
  public:
    /// Opens `path` (a regular file, checked by the caller); `what` names it in errors
    /// ("OBJ file"). Throws lucent::Error "path:0: cannot open ..." when it cannot be read.
    LineReader(std::string path, const char* what, LoadProgress progress = {},
               std::string stage = {});
    ~LineReader();
    LineReader(const LineReader&) = delete;
    LineReader& operator=(const LineReader&) = delete;

    /// The next line, without its '\n' or "\r\n"; false at the end of the file. Throws
    /// lucent::Error "path:line: ..." at a NUL byte or a line over kMaxLineBytes.
    bool next(std::string& line);
    /// The 1-based number of the line `next` returned last.
    size_t line_number() const { return m_line; }

  private:
    bool refill();

    std::string m_path, m_what, m_stage;
    LoadProgress m_progress;
    std::FILE* m_file = nullptr;
    std::vector<char> m_block;
    size_t m_pos = 0, m_end = 0, m_line = 0;
    uint64_t m_read = 0, m_size = 0;
};

}  // namespace lucent::scene
