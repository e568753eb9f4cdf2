#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "ardsim_description/mesh_io.h"
#include "ardsim_description/models.h"

using namespace ardsim_description;

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

}  // namespace

TEST(MeshIo, StlHoldsEveryTriangleWithItsWinding) {
  const TriangleMesh mesh = buildChaser();
  writeMesh(mesh, "chaser_test.STL");
  const std::string bytes = readAll("chaser_test.STL");
  ASSERT_EQ(bytes.size(), 84 + 50 * mesh.triangles.size());
  ASSERT_EQ(at<std::uint32_t>(bytes, 80), mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 97) {
    const std::size_t record = 84 + 50 * t;
    Eigen::Vector3f normal, corners[3];
    for (int k = 0; k < 3; ++k) normal[k] = at<float>(bytes, record + 4 * k);
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) corners[c][k] = at<float>(bytes, record + 12 + 12 * c + 4 * k);
      ASSERT_EQ(corners[c], mesh.vertices[mesh.triangles[t][c]]);
    }
    EXPECT_GT(normal.dot((corners[1] - corners[0]).cross(corners[2] - corners[0])), 0.0f);
  }
}

TEST(MeshIo, PlyHeaderCountsAndBodyMatchTheMesh) {
  const TriangleMesh mesh = buildHubble();
  writeMesh(mesh, "hubble_test.ply");
  const std::string bytes = readAll("hubble_test.ply");
  const std::size_t end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = bytes.substr(0, end);
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex " + std::to_string(mesh.vertices.size()) + "\n"), std::string::npos);
  EXPECT_NE(header.find("element face " + std::to_string(mesh.triangles.size()) + "\n"), std::string::npos);
  EXPECT_NE(header.find("comment part 0 " + mesh.parts[0].name), std::string::npos);
  const std::size_t body = end + std::strlen("end_header\n");
  const std::size_t face_bytes = 1 + 3 * 4 + 3 + 2 + 2;
  ASSERT_EQ(bytes.size(), body + 12 * mesh.vertices.size() + face_bytes * mesh.triangles.size());
  const std::size_t last_face = body + 12 * mesh.vertices.size() + face_bytes * (mesh.triangles.size() - 1);
  EXPECT_EQ(at<std::uint8_t>(bytes, last_face), 3);
  EXPECT_EQ(at<std::int32_t>(bytes, last_face + 1), mesh.triangles.back()[0]);
  EXPECT_EQ(at<std::uint16_t>(bytes, last_face + 16), mesh.triangle_material.back());
  EXPECT_EQ(at<std::uint16_t>(bytes, last_face + 18), mesh.triangle_part.back());
}

TEST(MeshIo, RejectsUnknownFormatsAndUnwritablePaths) {
  const TriangleMesh mesh = buildChaser();
  EXPECT_THROW(writeMesh(mesh, "chaser.obj"), std::invalid_argument);
  EXPECT_THROW(writeMesh(mesh, "no_extension"), std::invalid_argument);
  EXPECT_THROW(writeMesh(mesh, "/nonexistent-directory/chaser.stl"), std::runtime_error);
  TriangleMesh broken = mesh;
  broken.triangles.front()[0] = static_cast<int>(broken.vertices.size());
  EXPECT_THROW(writeMesh(broken, "broken.ply"), std::invalid_argument);
}
