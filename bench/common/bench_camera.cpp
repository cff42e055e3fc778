#include "bench/common/bench_camera.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "lucent/error.h"

namespace lucent::bench {

namespace fs = std::filesystem;

namespace {

float3 parse_float3(const std::string& text, const std::string& where) {
    float3 v;
    char c1 = 0, c2 = 0;
    std::istringstream in(text);
    if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',')
        throw Error(where + ": expected x,y,z but found '" + text + "'");
    return v;
}

}  // namespace

Camera find_camera(const std::string& scene) {
    fs::path file = fs::absolute(scene).lexically_normal();
    for (fs::path dir : {file.parent_path(), file.parent_path().parent_path()}) {
        fs::path list = dir / "cameras.txt";
        std::ifstream in(list);
        if (!in) continue;
        const std::string relative = file.lexically_relative(dir).generic_string();
        std::string line;
        for (int line_no = 1; std::getline(in, line); ++line_no) {
            std::istringstream fields(line);
            std::string name, eye, look, up, fov, light;
            if (!(fields >> name) || name[0] == '#' || name != relative) continue;
            const std::string where = list.string() + ":" + std::to_string(line_no);
            if (!(fields >> eye >> look >> up >> fov >> light))
                throw Error(where + ": expected file eye look up fov light");
            return Camera{parse_float3(eye, where), parse_float3(look, where),
                          parse_float3(up, where), std::stof(fov), parse_float3(light, where)};
        }
    }
    throw Error(scene +
                ": no viewpoint in cameras.txt beside the scene or one directory up; "
                "pass --eye, --look, --up, --fov and --light");
}

}  // namespace lucent::bench
