// A file as a std::streambuf that reports how much of it has been read, so that a parser
// taking an std::istream (tinyobjloader) shows progress through a large file.
#pragma once

#include <cstdio>
#include <streambuf>
#include <vector>

#include "scene/load_progress.h"

namespace lucent::scene {

class ProgressStreambuf : public std::streambuf {
  public:
    /// Opens `path` for reading; is_open() says whether it could.
    ProgressStreambuf(const std::string& path, LoadProgress progress, std::string stage);
    ~ProgressStreambuf() override;
    ProgressStreambuf(const ProgressStreambuf&) = delete;
    ProgressStreambuf& operator=(const ProgressStreambuf&) = delete;
    bool is_open() const { return m_file != nullptr; }

  protected:
    int_type underflow() override;

  private:
    std::FILE* m_file = nullptr;
    LoadProgress m_progress;
    std::string m_stage;
    std::vector<char> m_block;
    uint64_t m_read = 0, m_size = 0;
};

}  // namespace lucent::scene
