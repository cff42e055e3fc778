#include "scene/line_reader.h"

#include <cstring>

#include "lucent/error.h"
#include "scene/input_file.h"

namespace lucent::scene {

LineReader::LineReader(std::string path, const char* what, LoadProgress progress,
                       std::string stage)
    : m_path(std::move(path)),
      m_what(what),
      m_stage(std::move(stage)),
      m_progress(std::move(progress)),
      m_block(size_t(1) << 20) {
    m_file = std::fopen(m_path.c_str(), "rb");
    if (!m_file) throw Error(m_path + ":0: cannot open the " + m_what + " (check the path)");
    m_size = file_size(m_path);
}

LineReader::~LineReader() {
    if (m_file) std::fclose(m_file);
}

bool LineReader::refill() {
    m_pos = 0;
    m_end = std::fread(m_block.data(), 1, m_block.size(), m_file);
    m_read += m_end;
    if (m_progress) m_progress(m_stage, m_read, std::max(m_size, m_read));
    return m_end > 0;
}

bool LineReader::next(std::string& line) {
    line.clear();
    bool any = false;
    for (;;) {
        if (m_pos == m_end && !refill()) {
            if (any) ++m_line;  // a last line without '\n'
            return any;
        }
        any = true;
        const char* start = m_block.data() + m_pos;
        const size_t left = m_end - m_pos;
        const char* newline = static_cast<const char*>(std::memchr(start, '\n', left));
        const size_t take = newline ? size_t(newline - start) : left;
        if (std::memchr(start, '\0', take))
            throw Error(m_path + ":" + std::to_string(m_line + 1) + ": a NUL byte: this " +
                        m_what +
                        " holds binary data, not text (a damaged, sparse or misnamed file)");
        if (line.size() + take > kMaxLineBytes)
            throw Error(m_path + ":" + std::to_string(m_line + 1) + ": a line longer than " +
                        std::to_string(kMaxLineBytes) + " bytes; the " + m_what +
                        " is damaged or not text");
        line.append(start, take);
        m_pos += take;
        if (newline) {
            ++m_pos;
            ++m_line;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return true;
        }
    }
}

}  // namespace lucent::scene
