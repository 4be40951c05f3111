// Model loading: glTF axis convention, and the example model's closed solid volume.
#include "scene/models/triangle_mesh.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "scene/core/error.h"

namespace fs = std::filesystem;

namespace seasense::scene {
namespace {

// Signed volume of a closed mesh by the divergence theorem: Σ (a · (b × c)) / 6. Positive
// when every face is counter-clockwise seen from outside.
double SignedVolume(const TriangleMesh& m) {
    double v = 0.0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]),
            c(m.positions[m.indices[t + 2]]);
        v += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return v;
}

TEST(LoadModel, GltfAxesBecomeBodyAxes) {
    // One triangle at glTF (+X, +Y, +Z) = (1, 0, 0), (0, 2, 0), (0, 0, 3): glTF +X is the
    // model's left, +Y up, +Z forward (glTF 2.0 spec, "Coordinate System and Units").
    const fs::path dir =
        fs::temp_directory_path() / ("seasense_gltf_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const float pos[9] = {1, 0, 0, 0, 2, 0, 0, 0, 3};
    const uint16_t idx[4] = {0, 1, 2, 0};  // padded to 4-byte multiple
    {
        std::ofstream bin(dir / "tri.bin", std::ios::binary);
        bin.write(reinterpret_cast<const char*>(pos), sizeof pos);
        bin.write(reinterpret_cast<const char*>(idx), sizeof idx);
    }
    std::ofstream(dir / "tri.gltf") << R"({
      "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"uri": "tri.bin", "byteLength": 44}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                      {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 2, 3]},
        {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
    const TriangleMesh m = LoadModel(dir / "tri.gltf", 2.0);
    ASSERT_EQ(m.TriangleCount(), 1u);
    ASSERT_EQ(m.positions.size(), 3u);
    // Body axes: x right, y forward, z up; scaled by 2.
    EXPECT_EQ(m.positions[m.indices[0]], glm::vec3(-2, 0, 0));
    EXPECT_EQ(m.positions[m.indices[1]], glm::vec3(0, 0, 4));
    EXPECT_EQ(m.positions[m.indices[2]], glm::vec3(0, 6, 0));
    fs::remove_all(dir);
}

TEST(LoadModel, ExampleBoatIsAClosedOutwardFacingSolidOfTheScriptedVolume) {
    const TriangleMesh m =
        LoadModel(fs::path(SEASENSE_SOURCE_DIR) / "configs/models/patrol_boat.obj", 1.0);
    // Closed: every undirected edge (by position) is shared by exactly two triangles.
    std::map<std::pair<std::tuple<float, float, float>, std::tuple<float, float, float>>, int>
        edges;
    const auto key = [](const glm::vec3& p) { return std::make_tuple(p.x, p.y, p.z); };
    for (size_t t = 0; t < m.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            auto a = key(m.positions[m.indices[t + e]]);
            auto b = key(m.positions[m.indices[t + (e + 1) % 3]]);
            if (b < a) std::swap(a, b);
            ++edges[{a, b}];
        }
    for (const auto& [edge, count] : edges) EXPECT_EQ(count, 2);
    // Volumes of the three prisms scripts/make_example_model.py builds: hull pentagon
    // (5 × 15 rectangle + 5 × 5 / 2 bow triangle) × 2.6 m, bridge 3.6 × 6 × 2.6 m, and a
    // regular octagon of circumradius 0.6 m (area 2√2 r²) × 4.4 m.
    const double expected = 87.5 * 2.6 + 3.6 * 6.0 * 2.6 + 2.0 * std::sqrt(2.0) * 0.36 * 4.4;
    EXPECT_NEAR(SignedVolume(m), expected, 1e-3);
    // Bow forward (+y), beam across x, keel to stack top along z.
    glm::vec3 lo(1e9f), hi(-1e9f);
    for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    EXPECT_NEAR(hi.y, 10.0f, 1e-4f);
    EXPECT_NEAR(lo.y, -10.0f, 1e-4f);
    EXPECT_NEAR(hi.x - lo.x, 5.0f, 1e-4f);
    EXPECT_NEAR(lo.z, -1.0f, 1e-4f);
    EXPECT_NEAR(hi.z, 6.0f, 1e-4f);
}

TEST(LoadModel, UnreadableModelIsAnInputError) {
    EXPECT_THROW(LoadModel("/nonexistent/model.obj", 1.0), InputError);
    const fs::path bad =
        fs::temp_directory_path() / ("seasense_bad_" + std::to_string(::getpid()) + ".obj");
    std::ofstream(bad) << "this is not an obj file\n";
    EXPECT_THROW(LoadModel(bad, 1.0), InputError);
    fs::remove(bad);
}

}  // namespace
}  // namespace seasense::scene
