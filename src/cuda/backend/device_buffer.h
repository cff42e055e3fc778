// A block of device memory owned by one object (RAII over cuMemAlloc / cuMemFree), with
// synchronous host <-> device copies through the run-time loaded driver API.
#pragma once

#include <cuda.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>

namespace lucent::cuda {

class DeviceBuffer {
  public:
    DeviceBuffer() = default;
    /// Allocates `bytes` (nothing for 0). Throws lucent::Error without a driver.
    explicit DeviceBuffer(size_t bytes) { alloc(bytes); }
    ~DeviceBuffer() { reset(); }
    DeviceBuffer(DeviceBuffer&& other) noexcept { *this = std::move(other); }
    DeviceBuffer& operator=(DeviceBuffer&& other) noexcept;
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;

    /// Frees what it held and allocates `bytes` (keeps the block when the size is the same).
    void alloc(size_t bytes);
    /// Frees the block (no-op when empty).
    void reset() noexcept;
    /// Allocates `bytes` when needed and copies them from the host (synchronous).
    void upload(const void* data, size_t bytes);
    template <class T>
    void upload(std::span<const T> values) {
        upload(values.data(), values.size_bytes());
    }
    /// Copies the first `bytes` to the host (synchronous); bytes <= size().
    void download(void* data, size_t bytes) const;
    /// Sets every byte to `value`.
    void fill(unsigned char value);

    CUdeviceptr ptr() const { return m_ptr; }
    /// The device address as a typed pointer, for kernel parameter structs.
    template <class T>
    const T* as() const {
        return reinterpret_cast<const T*>(static_cast<uintptr_t>(m_ptr));
    }
    size_t size() const { return m_bytes; }
    bool empty() const { return m_bytes == 0; }

  private:
    CUdeviceptr m_ptr = 0;
    size_t m_bytes = 0;
};

}  // namespace lucent::cuda
