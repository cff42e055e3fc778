#include "cuda/embedded_sources.h"

namespace lucent::cuda {

const EmbeddedSource* find_embedded_source(std::string_view name) {
    for (const EmbeddedSource& s : embedded_sources()) {
        if (s.name == name) return &s;
        if (s.name.size() < name.size() && name.ends_with(s.name) &&
            name[name.size() - s.name.size() - 1] == '/')
            return &s;  // `name` is an absolute path (__FILE__) of an embedded module
    }
    return nullptr;
}

}  // namespace lucent::cuda
