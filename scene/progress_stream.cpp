#include "scene/progress_stream.h"

#include <algorithm>

#include "scene/input_file.h"

namespace lucent::scene {

ProgressStreambuf::ProgressStreambuf(const std::string& path, LoadProgress progress,
                                     std::string stage)
    : m_file(std::fopen(path.c_str(), "rb")),
      m_progress(std::move(progress)),
      m_stage(std::move(stage)),
      m_block(size_t(1) << 20),
      m_size(file_size(path)) {}

ProgressStreambuf::~ProgressStreambuf() {
    if (m_file) std::fclose(m_file);
}

ProgressStreambuf::int_type ProgressStreambuf::underflow() {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (!m_file) return traits_type::eof();
    const size_t n = std::fread(m_block.data(), 1, m_block.size(), m_file);
    if (n == 0) return traits_type::eof();
    m_read += n;
    if (m_progress) m_progress(m_stage, m_read, std::max(m_size, m_read));
    setg(m_block.data(), m_block.data(), m_block.data() + n);
    return traits_type::to_int_type(*gptr());
}

}  // namespace lucent::scene
