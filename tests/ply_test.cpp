// PLY meshes: ASCII and binary of both byte orders, faces fanned into triangles, and
// errors that name the header line or the element at fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "test_support.h"
#include "lucent/error.h"
#include "scene/scene.h"

namespace {

namespace fs = std::filesystem;

class Ply : public lucent_tests::TempDirTest {
  protected:
    static std::string error_of(const std::string& path) {
        try {
            lucent::scene::load_ply_mesh(path);
        } catch (const lucent::Error& e) {
            return e.what();
        }
        return "";
    }
};

const char* kQuadHeader =
    "ply\nformat ascii 1.0\ncomment a unit quad\nelement vertex 4\nproperty float x\n"
    "property float y\nproperty float z\nproperty float u\nproperty float v\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST_F(Ply, AsciiQuadIsFannedIntoTwoTriangles) {
    auto path = write("quad.ply", std::string(kQuadHeader) +
                                      "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n");
    auto mesh = lucent::scene::load_ply_mesh(path);
    ASSERT_EQ(mesh.positions.size(), 4u);
    ASSERT_EQ(mesh.indices.size(), 2u);
    EXPECT_EQ(mesh.indices[1].x, 0u);
    EXPECT_EQ(mesh.indices[1].z, 3u);
    ASSERT_EQ(mesh.uvs.size(), 4u);
    EXPECT_FLOAT_EQ(mesh.uvs[2].y, 1.f);
}

std::string binary_triangle(bool big_endian) {
    std::string s =
        std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
        " 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty double z\n"
        "element face 1\nproperty list uchar uint vertex_index\nend_header\n";
    auto put = [&](const void* p, size_t n) {
        std::string bytes(static_cast<const char*>(p), n);
        if (big_endian) std::reverse(bytes.begin(), bytes.end());  // the host is little-endian
        s += bytes;
    };
    const float xy[3][2] = {{0, 0}, {2, 0}, {0, 3}};
    for (int i = 0; i < 3; ++i) {
        put(&xy[i][0], 4);
        put(&xy[i][1], 4);
        double z = 5.0 + i;
        put(&z, 8);
    }
    unsigned char n = 3;
    s += char(n);
    for (unsigned i : {0u, 1u, 2u}) put(&i, 4);
    return s;
}

TEST_F(Ply, BinaryBothByteOrders) {
    for (bool big : {false, true}) {
        auto mesh = lucent::scene::load_ply_mesh(
            write(big ? "big.ply" : "little.ply", binary_triangle(big)));
        ASSERT_EQ(mesh.indices.size(), 1u) << big;
        EXPECT_FLOAT_EQ(mesh.positions[1].x, 2.f) << big;
        EXPECT_FLOAT_EQ(mesh.positions[2].y, 3.f) << big;
        EXPECT_FLOAT_EQ(mesh.positions[2].z, 7.f) << big;
    }
}

TEST_F(Ply, ErrorsNameTheLineOrElement) {
    EXPECT_NE(error_of(write("a.ply", "plyx\n")).find("a.ply:1:"), std::string::npos);
    auto no_end = write("b.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
    EXPECT_NE(error_of(no_end).find("end_header"), std::string::npos) << error_of(no_end);
    auto bad_type =
        write("c.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n");
    EXPECT_NE(error_of(bad_type).find("c.ply:4:"), std::string::npos) << error_of(bad_type);
    auto index = write("d.ply", std::string(kQuadHeader) +
                                    "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 1 9\n");
    EXPECT_NE(error_of(index).find("element 'face' 0"), std::string::npos) << error_of(index);
    std::string truncated = binary_triangle(false);
    truncated.resize(truncated.size() - 3);
    EXPECT_NE(error_of(write("e.ply", truncated)).find("ends early"), std::string::npos);
    auto nan = write("f.ply", std::string(kQuadHeader) +
                                  "0 0 nan 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n");
    EXPECT_NE(error_of(nan).find("not finite"), std::string::npos) << error_of(nan);
}

TEST_F(Ply, IndicesAndCountsThatAreNotWholeNumbersAreRefused) {
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list float float vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n";
    // A float index once truncated to a vertex (1.9 as 1); NaN and 1e300 were converted to
    // an integer for the message (undefined behaviour).
    for (const char* face : {"3 0 1 1.9\n", "3 0 1 nan\n", "3 0 1 1e300\n", "2.5 0 1 2\n"}) {
        const std::string error = error_of(write("g.ply", header + face));
        EXPECT_NE(error.find("element 'face' 0"), std::string::npos) << face << error;
        EXPECT_TRUE(error.find("not a whole number") != std::string::npos ||
                    error.find("out of range") != std::string::npos ||
                    error.find("a whole number, at most 1024") != std::string::npos)
            << face << error;
    }
    EXPECT_NE(error_of(write("h.ply", header + "3 0 1 1e300\n")).find("vertex index 1e+300 out of range"),
              std::string::npos);
    EXPECT_EQ(error_of(write("i.ply", header + "3 0 1 2\n")), "");  // float-typed but whole
}

TEST_F(Ply, CountsTheFileCannotHoldAreRefusedBeforeReading) {
    // 2^31 - 1 vertices declared in a file of a few bytes (it used to allocate and read on).
    auto huge = write("huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 2147483647\n"
                                  "property float x\nproperty float y\nproperty float z\n"
                                  "end_header\n0123456789ab");
    const std::string message = error_of(huge);
    EXPECT_NE(message.find("huge.ply"), std::string::npos) << message;
    EXPECT_NE(message.find("need at least 25769803764 bytes, but 12 follow"), std::string::npos)
        << message;
    // An element without properties whose items would take no bytes at all.
    auto empty = write("empty.ply", "ply\nformat ascii 1.0\nelement nothing 2000000000\n"
                                    "element vertex 0\nproperty float x\nproperty float y\n"
                                    "property float z\nend_header\n");
    EXPECT_NE(error_of(empty).find("element 'nothing' declares 2000000000 items but no properties"),
              std::string::npos)
        << error_of(empty);
}

TEST_F(Ply, BinaryDataWhereTextIsExpectedIsRefusedAtOnce) {
    // An ASCII header over 64 MiB of NUL bytes (the 1 GB one took 10.9 s and 4.1 GB
    // as one token), a header of zeros, an endless header line and an endless value.
    const std::string ascii =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string sparse = write("sparse.ply", ascii);
    fs::resize_file(sparse, 64u << 20);
    EXPECT_EQ(error_of(sparse), sparse + ": element 'vertex' 0: a NUL byte in an ASCII PLY: the "
                                         "file holds binary data, not text");
    const std::string zeros = write("zeros.ply", "ply\n" + std::string(8192, '\0'));
    EXPECT_EQ(error_of(zeros), zeros + ":2: a NUL byte in the header: not a PLY file, or a "
                                       "damaged one");
    const std::string long_line = write("long.ply", "ply\ncomment " + std::string(5000, 'x'));
    EXPECT_EQ(error_of(long_line), long_line + ":2: a line over 4096 bytes in the header: not a "
                                               "PLY file, or a damaged one");
    const std::string long_value = write("value.ply", ascii + std::string(100, '1') + " 0 0\n");
    EXPECT_EQ(error_of(long_value), long_value + ": element 'vertex' 0: a value longer than 64 "
                                                 "characters; the file is damaged");
}

TEST_F(Ply, ABinaryLoadReportsItsBytes) {
    // 100,000 vertices (1.2 MB) and one face: the body is read in 1 MiB blocks, each
    // reported, the last at the file's size.
    std::string body;
    for (int i = 0; i < 100000; ++i) {
        const float p[3] = {float(i), float(i % 7), 0.5f};
        body.append(reinterpret_cast<const char*>(p), sizeof p);
    }
    body += char(3);
    for (int i : {0, 1, 2}) body.append(reinterpret_cast<const char*>(&i), 4);
    const std::string path = write(
        "many.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 100000\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n" + body);
    std::vector<std::pair<uint64_t, uint64_t>> calls;
    const auto mesh = lucent::scene::load_ply_mesh(
        path, [&](const std::string& stage, uint64_t done, uint64_t total) {
            EXPECT_EQ(stage, "reading many.ply");
            calls.emplace_back(done, total);
        });
    ASSERT_EQ(mesh.positions.size(), 100000u);
    EXPECT_FLOAT_EQ(mesh.positions[99999].x, 99999.0f);
    EXPECT_FLOAT_EQ(mesh.positions[99999].y, float(99999 % 7));
    ASSERT_GE(calls.size(), 2u);
    EXPECT_EQ(calls.back().first, fs::file_size(path));
    EXPECT_EQ(calls.back().second, fs::file_size(path));
}

TEST_F(Ply, LoadSceneFramesAPlyMesh) {
    auto path = write("q.ply", std::string(kQuadHeader) +
                                   "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n");
    auto scene = lucent::scene::load_scene(path);
    EXPECT_EQ(scene.triangle_count(), 2u);
    EXPECT_EQ(scene.point_lights.size(), 1u);
    EXPECT_GT(scene.camera.eye.z, 1.f);
}

}  // namespace
