#include "cuda/backend/device_buffer.h"

#include <string>
#include <utility>

#include "cuda/backend/driver_api.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {
const DriverApi& api() {
    return require_driver("CUDA device memory");
}
}  // namespace

DeviceBuffer& DeviceBuffer::operator=(DeviceBuffer&& other) noexcept {
    if (this != &other) {
        reset();
        m_ptr = std::exchange(other.m_ptr, 0);
        m_bytes = std::exchange(other.m_bytes, 0);
    }
    return *this;
}

void DeviceBuffer::alloc(size_t bytes) {
    if (bytes == m_bytes && m_ptr) return;
    reset();
    if (bytes == 0) return;
    check(api().cuMemAlloc(&m_ptr, bytes), "cuMemAlloc");
    m_bytes = bytes;
}

void DeviceBuffer::reset() noexcept {
    if (m_ptr)
        if (const DriverApi* d = driver()) d->cuMemFree(m_ptr);  // errors here are not actionable
    m_ptr = 0;
    m_bytes = 0;
}

void DeviceBuffer::upload(const void* data, size_t bytes) {
    if (bytes != m_bytes) alloc(bytes);
    if (bytes) check(api().cuMemcpyHtoD(m_ptr, data, bytes), "cuMemcpyHtoD");
}

void DeviceBuffer::download(void* data, size_t bytes) const {
    if (bytes > m_bytes)
        throw Error("DeviceBuffer::download: " + std::to_string(bytes) + " bytes asked, " +
                    std::to_string(m_bytes) + " held");
    if (bytes) check(api().cuMemcpyDtoH(data, m_ptr, bytes), "cuMemcpyDtoH");
}

void DeviceBuffer::fill(unsigned char value) {
    if (m_bytes) check(api().cuMemsetD8(m_ptr, value, m_bytes), "cuMemsetD8");
}

}  // namespace lucent::cuda
