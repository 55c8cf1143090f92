// OBJ output: round trip through an independent parser (bit-exact floats),
// bad input, atomic writes, and one frame held in memory.

#include "deform/io/obj_writer.h"

#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>

#include "support/data_paths.h"
#include "support/exported_geometry.h"

namespace {

namespace fs = std::filesystem;

// A bent strip of n x 2 vertices with awkward float values.
struct Strip {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::uvec3> triangles;
};

Strip MakeStrip(int n, float phase) {
  Strip s;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < 2; ++j) {
      const float u = static_cast<float>(i) / 3.0f;
      s.positions.push_back({u * 0.1f + phase, std::sin(u + phase) * 1e-7f + 123.456f * static_cast<float>(j),
                             -std::numeric_limits<float>::min() * static_cast<float>(i)});
      s.normals.push_back(glm::normalize(glm::vec3(std::cos(u), 1.0f / 7.0f, phase)));
    }
    if (i + 1 < n) {
      const auto a = static_cast<unsigned>(2 * i);
      s.triangles.push_back({a, a + 2, a + 1});
      s.triangles.push_back({a + 1, a + 2, a + 3});
    }
  }
  return s;
}

TEST(ObjWriter, RoundTripIsBitExact) {
  const fs::path dir = testsupport::FreshOutputDir("obj_writer/round_trip");
  const Strip s = MakeStrip(17, 0.3f);
  deform::ObjSequenceWriter w;
  const std::string path = (dir / "mesh_0001.obj").string();
  ASSERT_TRUE(w.Write({.positions = s.positions, .normals = s.normals, .triangles = s.triangles,
                       .comment = "two\nlines"},
                      path));
  const testsupport::ParsedObj p = testsupport::ParseObjFile(path);
  ASSERT_TRUE(p.error.empty()) << p.error;
  ASSERT_EQ(p.positions.size(), s.positions.size());
  ASSERT_EQ(p.normals.size(), s.normals.size());
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(p.positions[i][c], s.positions[i][c]) << i;  // shortest round-trip text
      EXPECT_EQ(p.normals[i][c], s.normals[i][c]) << i;
    }
  }
  EXPECT_EQ(p.triangles, s.triangles);
  EXPECT_EQ(p.normal_indices, s.triangles);  // vertex i uses normal i
}

TEST(ObjWriter, WithoutNormalsWritesPlainFaces) {
  const fs::path dir = testsupport::FreshOutputDir("obj_writer/no_normals");
  const Strip s = MakeStrip(3, 0.0f);
  deform::ObjSequenceWriter w;
  const std::string path = (dir / "a.obj").string();
  ASSERT_TRUE(w.Write({.positions = s.positions, .triangles = s.triangles}, path));
  const testsupport::ParsedObj p = testsupport::ParseObjFile(path);
  ASSERT_TRUE(p.error.empty()) << p.error;
  EXPECT_TRUE(p.normals.empty());
  EXPECT_TRUE(p.normal_indices.empty());
  EXPECT_EQ(p.triangles, s.triangles);
}

TEST(ObjWriter, BadInputIsAnErrorAndWritesNothing) {
  const fs::path dir = testsupport::FreshOutputDir("obj_writer/bad");
  Strip s = MakeStrip(3, 0.0f);
  deform::ObjSequenceWriter w;
  const std::string path = (dir / "bad.obj").string();

  std::vector<glm::uvec3> tris = s.triangles;
  tris[1].z = static_cast<unsigned>(s.positions.size());
  base::Status st = w.Write({.positions = s.positions, .triangles = tris}, path);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().code, base::ErrorCode::kInvalidArgument);
  EXPECT_NE(st.error().ToString().find("bad.obj"), std::string::npos);
  EXPECT_NE(st.error().message.find("triangle 1"), std::string::npos);

  s.positions[2].y = std::numeric_limits<float>::quiet_NaN();
  st = w.Write({.positions = s.positions, .triangles = s.triangles}, path);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("finite"), std::string::npos);

  const std::vector<glm::vec3> short_normals(2, glm::vec3(0, 0, 1));
  s = MakeStrip(3, 0.0f);
  st = w.Write({.positions = s.positions, .normals = short_normals, .triangles = s.triangles}, path);
  ASSERT_FALSE(st);
  EXPECT_TRUE(fs::is_empty(dir));  // neither the file nor a temporary
}

TEST(ObjWriter, MissingFolderIsAnIoErrorNamingTheFile) {
  const fs::path dir = testsupport::FreshOutputDir("obj_writer/missing");
  const Strip s = MakeStrip(3, 0.0f);
  deform::ObjSequenceWriter w;
  const std::string path = (dir / "no" / "such" / "a.obj").string();
  const base::Status st = w.Write({.positions = s.positions, .triangles = s.triangles}, path);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().code, base::ErrorCode::kIo);
  EXPECT_NE(st.error().ToString().find("a.obj"), std::string::npos);
}

// The writer keeps one frame's text: writing 60 frames holds no more than one.
TEST(ObjWriter, MemoryDoesNotGrowWithFrames) {
  const fs::path dir = testsupport::FreshOutputDir("obj_writer/memory");
  deform::ObjSequenceWriter w;
  Strip s = MakeStrip(200, 0.0f);
  ASSERT_TRUE(w.Write({.positions = s.positions, .normals = s.normals, .triangles = s.triangles},
                      (dir / "f0.obj").string()));
  const std::size_t after_one = w.buffer_bytes();
  EXPECT_GT(after_one, 0u);
  std::size_t largest_file = 0;
  for (int f = 1; f < 60; ++f) {
    s = MakeStrip(200, 0.01f * static_cast<float>(f));
    std::string file = "f";
    file += std::to_string(f);
    file += ".obj";
    const fs::path p = dir / file;
    ASSERT_TRUE(w.Write({.positions = s.positions, .normals = s.normals, .triangles = s.triangles},
                        p.string()));
    largest_file = std::max<std::size_t>(largest_file, fs::file_size(p));
  }
  // The buffer never exceeds what one frame needs (capacity doubling aside).
  EXPECT_LE(w.buffer_bytes(), 2 * largest_file);
  EXPECT_LE(w.buffer_bytes(), 2 * after_one);
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

}  // namespace
